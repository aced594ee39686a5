"""Runs a documentation example as a reader would and checks both its exit status (0) and that
its output matches a pattern (ctest's PASS_REGULAR_EXPRESSION alone would ignore the status).

Usage: run_example.py --expect REGEX -- EXAMPLE.py [ARGS...]
       run_example.py --expect REGEX -- DOC.md     (runs the first ```python block of DOC.md)"""

import argparse
import os
import re
import subprocess
import sys
import tempfile


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--expect", required=True, help="regular expression the stdout must match")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no example given")
    with tempfile.TemporaryDirectory() as tmp:
        if command[0].endswith(".md"):
            with open(command[0], encoding="utf-8") as f:
                blocks = re.findall(r"```python\n(.*?)```", f.read(), re.S)
            if not blocks:
                print(f"run_example: no ```python block in {command[0]}")
                return 1
            script = os.path.join(tmp, "example.py")
            with open(script, "w", encoding="utf-8") as f:
                f.write(blocks[0])
            command = [script] + command[1:]
        result = subprocess.run([sys.executable] + command, capture_output=True, text=True)
    sys.stdout.write(result.stdout)
    sys.stderr.write(result.stderr)
    if result.returncode != 0:
        print(f"run_example: {command[0]} exited with status {result.returncode}")
        return 1
    if not re.search(args.expect, result.stdout):
        print(f"run_example: the output of {command[0]} does not match {args.expect!r}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
