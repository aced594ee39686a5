#!/usr/bin/env python3
"""The hostile-file suite (docs/reliability.md): every generic kind of hostile file applied to every
file dualgrid reads, as listed in one place, tests/hostile/file_inputs.tsv (its header explains
the rows). Each case must end within its time limit with exit code 2 (command line) or a
ValueError / OSError (Python, interpreter alive), printing exactly one error line that names the
replaced file; none may crash, hang or be accepted.

Usage:
  file_inputs.py --dualgrid BIN --networks DIR --fixture-python PY [--python PY] [--only cli|py]
  file_inputs.py --check-complete --dualgrid BIN
      fails when a file argument of a command (its --help) or of the Python module
      (python/dualgrid/_dualgrid.pyi) has no line in the table.
--python: the interpreter that imports the installed module (PYTHONPATH set by the caller).
--fixture-python: the interpreter with h5py and numpy, for the RadarScenes and nuScenes fixtures.
"""
import argparse
import concurrent.futures
import glob
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
TABLE = os.path.join(HERE, "file_inputs.tsv")
TIME_LIMIT = 60  # [s] per case: far above any refusal (all take well under a second)
KINDS = {
    "file": ["fifo", "dev_zero", "dev_null", "directory", "loop", "dangling", "empty",
             "truncated", "garbage", "oversize"],
    "numbers": ["nan", "inf", "absurd"],
    "folder": ["fifo", "dev_null", "regular", "loop", "dangling"],
}
# Kinds that leave the input as it is and put the command's output ({O}) on it: the output equal
# to the row's file or folder, and inside it (under a file: a path that cannot be made). Refused
# by the output guard (docs/reliability.md, "Output folders") with the input left byte for byte.
OUTPUT_KINDS = ["out_is_input", "out_inside_input"]
# A number of a text file: not part of a word (radar_1, v1.0-mini keep their digits).
NUMBER = re.compile(r"(?<![\w.\-])-?\d+(\.\d+)?([eE][-+]?\d+)?(?![\w.])")
REPLACEMENT = {"nan": "nan", "inf": "inf", "absurd": "1e300"}


def read_table():
    rows, args = [], {}
    with open(TABLE, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            if line.startswith("@"):
                word = line.split()
                args[word[1]] = word[0]
                continue
            fields = [x.strip() for x in line.split(" | ")]
            if len(fields) != 6:
                sys.exit(f"{TABLE}:{n}: expected 6 fields separated by ' | ', got {len(fields)}")
            rid, arg, fixture, path, kinds, command = fields
            # "file numbers -absurd": the groups' kinds less the ones named with '-' (the
            # table says why next to the row).
            words = kinds.split()
            kind_list = [k for g in words if not g.startswith("-") for k in KINDS[g]]
            kind_list = [k for k in kind_list if "-" + k not in words]
            # An output on the input (every row with an output path): the output guard's kinds.
            if "{O}" in command:
                kind_list += [k for k in OUTPUT_KINDS if "-" + k not in words]
            rows.append(dict(id=rid, arg=arg, fixture=fixture, file=path, kinds=kind_list,
                             command=command))
            args[arg] = "row"
    return rows, args


def help_arguments(dualgrid):
    """(command:option) for every argument typed FILE, DIR or PATH, or named like a file."""
    out = subprocess.run([dualgrid, "--help"], capture_output=True, text=True).stdout
    commands = re.findall(r"^  (\w+)\s", out.split("Subcommands:")[-1], re.M)
    found = set()
    for c in commands:
        text = subprocess.run([dualgrid, c, "--help"], capture_output=True, text=True).stdout
        for m in re.finditer(r"^  (?:-\w,)?(--?[\w-]+|\w+) TEXT(:FILE|:DIR|:PATH)?\b(.*)$", text,
                             re.M):
            name, typed, rest = m.group(1), m.group(2), m.group(3)
            if typed or re.search(r"\b(file|folder)\b", rest, re.I):
                found.add(f"{c}:{name}")
    return found


def stub_arguments():
    """py:function:parameter for every StrPath parameter of the module's stubs."""
    text = open(os.path.join(REPO, "python", "dualgrid", "_dualgrid.pyi"), encoding="utf-8").read()
    found = set()
    owner = None
    for m in re.finditer(r"^(class (\w+)|(\s*)def (\w+)\((.*?)\)\s*(->|:))", text, re.M | re.S):
        if m.group(2):
            owner = m.group(2)
            continue
        name = m.group(4)
        if m.group(3) == "":
            owner = None
        target = owner if name == "__init__" and owner else name
        for p in re.finditer(r"(\w+):\s*StrPath", m.group(5)):
            found.add(f"py:{target}:{p.group(1)}")
    return found


def check_complete(dualgrid):
    _, args = read_table()
    missing = sorted((help_arguments(dualgrid) | stub_arguments()) - set(args))
    for a in missing:
        print(f"FAIL {a}: a file argument with no line in {TABLE}")
    print(f"{len(args)} arguments listed, {len(missing)} missing")
    return 1 if missing else 0


def make_fixtures(work, dualgrid, networks, fixture_python):
    """The good inputs every case starts from."""
    fx = os.path.join(work, "fixtures")
    os.makedirs(fx)
    rec = os.path.join(REPO, "tests", "recorded")
    subprocess.run([fixture_python, os.path.join(rec, "make_radarscenes.py"), "--out",
                    os.path.join(fx, "rs"), "--duration", "1"], check=True, capture_output=True)
    subprocess.run([fixture_python, os.path.join(rec, "make_nuscenes.py"), "--out",
                    os.path.join(fx, "nus"), "--duration", "2"], check=True, capture_output=True)
    highway = os.path.join(REPO, "scenarios", "highway.yaml")
    subprocess.run([dualgrid, "sim", highway, "--out", os.path.join(fx, "run"), "--detections",
                    "exact", "--duration", "1", "-q", "--network-dir", networks], check=True,
                   capture_output=True)
    scen = os.path.join(fx, "scen")
    os.makedirs(scen)
    shutil.copy(highway, scen)
    with open(os.path.join(scen, "suite.yaml"), "w") as f:
        # The scenario last: a truncated copy lacks it (a suite cut at a line is still a suite).
        f.write("name: hostile\ncases:\n  - name: a\n    modes: [dual]\n    duration: 0.1\n"
                "    seeds: 1\n    first_seed: 1\n    scenario: highway.yaml\n")
    os.makedirs(os.path.join(scen, "networks"))
    for net in glob.glob(os.path.join(networks, "*.net.xml")):
        shutil.copy(net, os.path.join(scen, "networks"))
    shutil.copytree(os.path.join(fx, "rs"), os.path.join(scen, "rs"))
    make_sumo_fixture(os.path.join(fx, "sumo"), networks)
    subprocess.run([dualgrid, "sweep", highway, "--set", "filter.sigma_v=1,2", "--seeds", "1",
                    "--duration", "0.1", "--emit", "list", "-q", "--network-dir", networks,
                    "--out", os.path.join(fx, "sweep")], check=True, capture_output=True)
    return fx


def make_sumo_fixture(sumo, networks):
    """A user's own SUMO files: a network, a route file, an additional file and a .sumocfg, with
    a scenario on each way of giving them (traffic.route_files, sumo_config)."""
    os.makedirs(sumo)
    shutil.copy(os.path.join(networks, "highway.net.xml"), sumo)
    files = {
        "ok.rou.xml": '<routes>\n<vehicle id="v0" depart="0" departLane="1" departPos="300">\n'
                      '  <route edges="east_1 east_2"/>\n</vehicle>\n</routes>\n',
        "ok.add.xml": "<additional>\n</additional>\n",
        "ok.sumocfg": '<configuration>\n  <input>\n    <net-file value="highway.net.xml"/>\n'
                      '    <route-files value="ok.rou.xml"/>\n  </input>\n</configuration>\n',
        "routes.yaml": "name: routes\nnetwork: highway.net.xml\nego: {from_routes: v0}\n"
                       "traffic: {route_files: [ok.rou.xml], additional_files: [ok.add.xml]}\n",
        "config.yaml": "name: config\nsumo_config: ok.sumocfg\nego: {from_routes: v0}\n",
    }
    for name, text in files.items():
        with open(os.path.join(sumo, name), "w") as f:
            f.write(text)


def make_hostile(path, kind, good):
    """Replaces `path` (a copy of the good input `good`, now removed) by the hostile kind."""
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path)
    elif os.path.lexists(path):
        os.remove(path)
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dev_zero":
        os.symlink("/dev/zero", path)
    elif kind == "dev_null":
        os.symlink("/dev/null", path)
    elif kind == "directory":
        os.mkdir(path)
    elif kind == "loop":
        os.symlink(os.path.basename(path), path)
    elif kind == "dangling":
        os.symlink(os.path.basename(path) + ".nowhere", path)
    elif kind in ("empty", "regular"):
        open(path, "wb").close()
    elif kind == "truncated":
        with open(path, "wb") as f:
            f.write(good[: len(good) // 2])
    elif kind == "garbage":
        with open(path, "wb") as f:
            f.write(bytes((i * 7919 + 13) % 256 for i in range(3000)))
    elif kind == "oversize":  # sparse: 1 GiB + 1 MiB of zeros, over every cap of a file read
        with open(path, "wb") as f:
            f.truncate((1 << 30) + (1 << 20))
    else:
        text = good.decode("utf-8", errors="replace")
        lines = text.split("\n")
        # A CSV's header keeps its words; every number after it is replaced.
        first = 1 if path.endswith(".csv") else 0
        body = "\n".join(NUMBER.sub(REPLACEMENT[kind], x) for x in lines[first:])
        with open(path, "w", encoding="utf-8") as f:
            f.write("\n".join(lines[:first] + [body]) if first else body)


def tree_digest(root):
    """Every path under ROOT with its kind and, for regular files, its bytes' digest."""
    h = hashlib.sha1()
    for folder, dirs, files in sorted(os.walk(root)):
        dirs.sort()
        for name in sorted(dirs + files):
            path = os.path.join(folder, name)
            h.update(os.path.relpath(path, root).encode())
            if os.path.isfile(path) and not os.path.islink(path):
                with open(path, "rb") as f:
                    h.update(hashlib.sha1(f.read()).digest())
            else:
                h.update(b"link" if os.path.islink(path) else b"dir")
    return h.hexdigest()


def run_case(row, kind, fx, work, opts):
    case = os.path.join(work, "cases", f"{row['id']}.{kind}")
    out = case + ".out"
    src = os.path.join(fx, row["fixture"])
    shutil.copytree(src, case, symlinks=True)
    matches = sorted(glob.glob(os.path.join(case, row["file"])))
    target = os.path.normpath(matches[0] if matches else os.path.join(case, row["file"]))
    good = b""
    if os.path.isfile(target):
        with open(target, "rb") as f:
            good = f.read()
    before = None
    if kind in OUTPUT_KINDS:
        out = target if kind == "out_is_input" else os.path.join(target, "run")
        before = tree_digest(case)
    else:
        make_hostile(target, kind, good)
    command = (row["command"].replace("{C}", case).replace("{F}", target)
               .replace("{O}", out).replace("{N}", opts.networks))
    if row["arg"].startswith("py:"):
        program = ("import sys, dualgrid\ntry:\n    " + command + "\n"
                   "except (ValueError, OSError) as e:\n"
                   "    print('dualgrid: error: ' + str(e).replace(chr(10), ' '))\n"
                   "    sys.exit(2)\n")
        argv = [opts.python, "-c", program]
    else:
        argv = [opts.dualgrid] + command.split()
    start = time.monotonic()
    try:
        p = subprocess.run(argv, capture_output=True, text=True, errors="replace",
                           timeout=TIME_LIMIT, cwd=work, stdin=subprocess.DEVNULL)
        rc, text = p.returncode, (p.stdout + p.stderr).strip()
    except subprocess.TimeoutExpired:
        rc, text = None, ""
    elapsed = time.monotonic() - start
    lines = [x for x in text.split("\n") if x.strip()]
    name = os.path.basename(target)
    why = ""
    if rc is None:
        why = f"hung (killed after {TIME_LIMIT} s)"
    elif rc < 0 or rc >= 128:
        why = f"crashed (signal {-rc if rc < 0 else rc - 128})"
    elif rc != 2:
        why = f"exit code {rc}, expected 2"
    elif len(lines) != 1:
        why = f"printed {len(lines)} lines, expected one"
    elif not lines[0].startswith("dualgrid: error: "):
        why = "not a 'dualgrid: error:' line"
    elif name not in lines[0]:
        why = f"the line does not name {name}"
    elif before is not None and tree_digest(case) != before:
        why = "the input changed"
    if before is not None:
        out = case + ".out"  # the output was the input: nothing else to remove
    for path in (case, out, out + ".png"):  # the case itself may now be a FIFO or a link
        if os.path.isdir(path) and not os.path.islink(path):
            shutil.rmtree(path, ignore_errors=True)
        elif os.path.lexists(path):
            os.remove(path)
    return f"{row['id']}.{kind}", why, " ".join(lines)[:400], elapsed


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dualgrid", required=True)
    ap.add_argument("--networks")
    ap.add_argument("--fixture-python", default="/usr/bin/python3")
    ap.add_argument("--python", default=sys.executable)
    ap.add_argument("--only", choices=["cli", "py"])
    ap.add_argument("--rows", help="a regular expression: only the rows whose id matches")
    ap.add_argument("--kinds", help="a regular expression: only the kinds that match")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--check-complete", action="store_true")
    opts = ap.parse_args()
    opts.dualgrid = os.path.abspath(opts.dualgrid)
    if opts.check_complete:
        return check_complete(opts.dualgrid)
    rows, _ = read_table()
    rows = [r for r in rows if opts.only is None or r["arg"].startswith("py:") == (opts.only == "py")]
    if opts.rows:
        rows = [r for r in rows if re.search(opts.rows, r["id"])]
    work = tempfile.mkdtemp(prefix="dualgrid_file_inputs.")
    try:
        fx = make_fixtures(work, opts.dualgrid, opts.networks, opts.fixture_python)
        os.makedirs(os.path.join(work, "cases"))
        cases = [(r, k) for r in rows for k in r["kinds"]
                 if opts.kinds is None or re.search(opts.kinds, k)]
        failed, slowest = 0, (0.0, "")
        with concurrent.futures.ThreadPoolExecutor(max_workers=opts.jobs) as pool:
            futures = [pool.submit(run_case, r, k, fx, work, opts) for r, k in cases]
            for f in futures:
                name, why, text, elapsed = f.result()
                slowest = max(slowest, (elapsed, name))
                if why:
                    failed += 1
                    print(f"FAIL {name}: {why}\n  output: {text}")
        print(f"{len(cases) - failed} of {len(cases)} hostile file cases passed "
              f"({len(rows)} rows; slowest {slowest[1]}, {slowest[0]:.1f} s)")
        return 1 if failed else 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
