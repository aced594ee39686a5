"""Runs a documentation example as a reader would and checks both its exit status (0) and that
its output matches a pattern (ctest's PASS_REGULAR_EXPRESSION alone would ignore the status).

Usage: run_example.py --expect REGEX -- EXAMPLE.py [ARGS...]"""

import argparse
import re
import subprocess
import sys


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--expect", required=True, help="regular expression the stdout must match")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no example given")
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
