#!/usr/bin/env python3
"""`dualgrid filter` on a RadarScenes sequence written by h5py from the public schema
(make_radarscenes.py, not our writer) tracks its moving car and writes the run folder.

The sequence: a car 14 m/s on the lane left of an ego at 10 m/s, 3-6 points per scan of the
radars that see it, static reflectors along the road (make_radarscenes.py). Expected, with a
margin for the first second (a track needs a few cycles to form, docs/algorithm.md):
- objects.csv: the dual mode tracks 'car-1' for most of the run (D >= 0.6) with the right
  velocity for at least half of it (D_v >= 0.5);
- clusters.csv: after the first 1.5 s, in >= 80 % of the dual cycles a cluster lies within 3 m
  of the car (its points are spread over its box) moving within 2 m/s of its velocity;
- points: precision >= 0.8 (static reflectors rarely in dynamic cells) and recall >= 0.5.
Then, on 3 s of the same sequence (dual mode, no figures):
- widths: the file with every field at another width and byte order (make_radarscenes.py
  --widths wide, the same values) gives the same clusters.csv and metrics.json, bit for bit;
- sensors.json: moved away from the dataset root, the run stops with exit 2 and one line naming
  the missing file; given with --sensors, the run equals the one that found it in the root;
- without labels (no label_id, no track_id): the run completes, metrics.json has no point scores,
  and the table says what cannot be scored.
Usage: check_radarscenes.py DUALGRID
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
import make_radarscenes as gen  # noqa: E402


def fail(msg):
    sys.exit("FAIL: " + msg)


def main():
    binary = sys.argv[1]
    work = tempfile.mkdtemp(prefix="dualgrid_radarscenes.", dir=os.environ.get("TMPDIR"))
    root = os.path.join(work, "rs")
    subprocess.run([sys.executable, os.path.join(here, "make_radarscenes.py"), "--out", root],
                   check=True, capture_output=True)
    out = os.path.join(work, "run")
    r = subprocess.run([binary, "filter", os.path.join(root, "data", "sequence_1"), "--out", out,
                        "-q"], capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"filter exited {r.returncode}: {r.stderr.strip()}")
    for f in ("summary.json", "metrics.json", "table.md", "clusters.csv", "objects.csv",
              "grid.csv", "ground_truth.csv", "config.json", "replay/index.json",
              "figures/tracked_share.png"):
        if not os.path.isfile(os.path.join(out, f)):
            fail(f"the run folder has no {f}")
    if not any(n.startswith("grid_t") and n.endswith(".png")
               for n in os.listdir(os.path.join(out, "figures"))):
        fail("no grid figure")
    summary = json.load(open(os.path.join(out, "summary.json")))
    if not summary.get("complete") or summary["input"]["kind"] != "radarscenes":
        fail(f"summary: {summary.get('status')} {summary.get('input')}")
    metrics = json.load(open(os.path.join(out, "metrics.json")))
    points = metrics["modes"]["dual"]["points"]
    print("dual points:", {k: points[k] for k in ("precision", "recall", "f1")})
    if not (points["precision"] >= 0.8 and points["recall"] >= 0.5):
        fail(f"point scores of dual: {points}")
    rows = [row for row in csv.DictReader(open(os.path.join(out, "objects.csv")))
            if row["mode"] == "dual" and row["name"] == "car-1"]
    if not rows:
        fail("objects.csv has no row for car-1 in mode dual")
    d, dv = float(rows[0]["D"]), float(rows[0]["D_v"])
    print(f"car-1 (dual): D {d:.3f}, D_v {dv:.3f}")
    if not (d >= 0.6 and dv >= 0.5):
        fail(f"car-1 tracked too little: D {d}, D_v {dv}")
    by_time = {}
    for row in csv.DictReader(open(os.path.join(out, "clusters.csv"))):
        if row["mode"] == "dual":
            by_time.setdefault(float(row["time"]), []).append(row)
    cycles = sorted({float(row["time"]) for row in csv.DictReader(open(
        os.path.join(out, "grid.csv")))})
    late = [t for t in cycles if t >= 1.5]
    hits = 0
    for t in late:
        c = gen.car_centre(t)
        v = (gen.CAR_SPEED * math.cos(gen.HEADING), gen.CAR_SPEED * math.sin(gen.HEADING))
        hits += any(math.hypot(float(k["x"]) - c[0], float(k["y"]) - c[1]) <= 3.0 and
                    math.hypot(float(k["vx"]) - v[0], float(k["vy"]) - v[1]) <= 2.0
                    for k in by_time.get(t, []))
    share = hits / max(1, len(late))
    print(f"cycles after 1.5 s with a cluster on the car: {hits}/{len(late)} ({share:.2f})")
    if share < 0.8:
        fail(f"the car is tracked in {share:.2f} of the late cycles (>= 0.8 expected)")
    check_replay_words(binary, out)
    check_variants(binary, work)
    subprocess.run(["rm", "-rf", work])


def check_replay_words(binary, out):
    """The replay names the references as the figures do: tracks estimated from labelled
    points, never SUMO's ground truth (docs/replay.md)."""
    index = json.load(open(os.path.join(out, "replay", "index.json")))
    if index.get("truth_label") != "track estimate":
        fail(f"replay/index.json truth_label: {index.get('truth_label')!r}, not 'track estimate'")
    r = subprocess.run([binary, "replay", out, "--html", "-q"], capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"replay --html exited {r.returncode}: {r.stderr.strip()}")
    page = read(os.path.join(out, "replay.html"))
    if '"truth_label":"track estimate"' not in page:
        fail("the viewer page does not carry the recording's truth_label")


def make(root, *extra):
    subprocess.run([sys.executable, os.path.join(here, "make_radarscenes.py"), "--out", root,
                    "--duration", "3", *extra], check=True, capture_output=True)
    return os.path.join(root, "data", "sequence_1")


def short_run(binary, seq, out, *extra):
    return subprocess.run([binary, "filter", seq, "--out", out, "--modes", "dual", "--no-figures",
                           "-q", *extra], capture_output=True, text=True)


def read(path):
    with open(path) as f:
        return f.read()


def check_variants(binary, work):
    narrow = make(os.path.join(work, "narrow"))
    ref = os.path.join(work, "run_narrow")
    r = short_run(binary, narrow, ref)
    if r.returncode != 0:
        fail(f"filter (narrow) exited {r.returncode}: {r.stderr.strip()}")
    if len(read(os.path.join(ref, "clusters.csv")).splitlines()) < 10:
        fail("the 3 s narrow run has fewer than 9 clusters: nothing to compare")

    # Widths: the same values at other widths and byte orders read the same.
    wide = make(os.path.join(work, "wide"), "--widths", "wide")
    out = os.path.join(work, "run_wide")
    r = short_run(binary, wide, out)
    if r.returncode != 0:
        fail(f"filter (wide) exited {r.returncode}: {r.stderr.strip()}")
    for f in ("clusters.csv", "metrics.json"):
        if read(os.path.join(out, f)) != read(os.path.join(ref, f)):
            fail(f"the wide file's {f} differs from the narrow file's")
    print("widths: narrow and wide files give the same clusters.csv and metrics.json")

    # sensors.json: not in the dataset root -> exit 2 naming it; --sensors -> the same run.
    moved = os.path.join(work, "sensors_elsewhere.json")
    os.rename(os.path.join(work, "narrow", "sensors.json"), moved)
    r = short_run(binary, narrow, os.path.join(work, "run_nosensors"))
    lines = r.stderr.strip().splitlines()
    if r.returncode != 2 or len(lines) != 1 or "sensors.json" not in lines[0]:
        fail(f"without sensors.json: exit {r.returncode}, stderr {r.stderr!r} "
             "(expected exit 2 and one line naming sensors.json)")
    out = os.path.join(work, "run_sensors")
    r = short_run(binary, narrow, out, "--sensors", moved)
    if r.returncode != 0:
        fail(f"filter --sensors exited {r.returncode}: {r.stderr.strip()}")
    if read(os.path.join(out, "clusters.csv")) != read(os.path.join(ref, "clusters.csv")):
        fail("--sensors FILE gives other clusters than sensors.json in the dataset root")
    print("sensors.json: missing -> " + lines[0] + "; --sensors gives the same clusters")

    # Without labels: the run completes and says what it cannot score.
    unlabelled = make(os.path.join(work, "nolabels"), "--labels", "none")
    out = os.path.join(work, "run_nolabels")
    r = short_run(binary, unlabelled, out)
    if r.returncode != 0:
        fail(f"filter (no labels) exited {r.returncode}: {r.stderr.strip()}")
    metrics = json.load(open(os.path.join(out, "metrics.json")))
    if "points" in metrics["modes"]["dual"]:
        fail("unlabelled data have point scores")
    summary = json.load(open(os.path.join(out, "summary.json")))
    if summary["input"]["labels"] or not summary.get("complete"):
        fail(f"unlabelled run: summary input {summary['input']}, complete {summary.get('complete')}")
    if "without labels" not in read(os.path.join(out, "table.md")):
        fail("the unlabelled run's table does not say what it cannot score")
    if len(read(os.path.join(out, "clusters.csv")).splitlines()) < 10:
        fail("the unlabelled run tracks nothing")
    print("without labels: complete, no point scores, the table says so")


if __name__ == "__main__":
    main()
