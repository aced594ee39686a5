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
        v = gen.CAR_SPEED * (math.cos(gen.HEADING), math.sin(gen.HEADING))
        hits += any(math.hypot(float(k["x"]) - c[0], float(k["y"]) - c[1]) <= 3.0 and
                    math.hypot(float(k["vx"]) - v[0], float(k["vy"]) - v[1]) <= 2.0
                    for k in by_time.get(t, []))
    share = hits / max(1, len(late))
    print(f"cycles after 1.5 s with a cluster on the car: {hits}/{len(late)} ({share:.2f})")
    if share < 0.8:
        fail(f"the car is tracked in {share:.2f} of the late cycles (>= 0.8 expected)")
    subprocess.run(["rm", "-rf", work])


if __name__ == "__main__":
    main()
