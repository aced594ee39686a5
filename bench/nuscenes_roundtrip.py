#!/usr/bin/env python3
"""How close `filter` on a nuScenes export comes to the run (docs/recorded-data.md, "nuScenes",
"Round trip"), and how far the annotations' reference velocities lie from SUMO's truth.

For each scenario: `run` (--detections exact), `export --format nuscenes` with float32 (the
published files') and float64 PCD fields, `filter` on both. Per export it counts the cycles (step
and mode) whose clusters equal the run's to the printed digits (all columns; all but the weight;
the same count with every position within 0.1 m and velocity within 0.1 m/s), and the first
cycle that differs. It then compares the references the filter scored against (the
annotations, interpolated) with SUMO's truth at every cycle, and D, D_v per mode; and the same
for a RadarScenes export, whose references are estimated from the labelled points.

Usage: nuscenes_roundtrip.py DUALGRID NETWORK_DIR DURATION SCENARIO...
"""
import csv
import json
import os
import subprocess
import sys
import tempfile
from collections import defaultdict


def run(*args):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(args)} exited {r.returncode}: {r.stderr.strip()}")


def cycles(path):
    out = defaultdict(list)
    with open(path) as f:
        for r in csv.DictReader(f):
            out[(int(r["step"]), r["mode"])].append(r)
    return out


def agreement(ref, got):
    keys = ("x", "y", "vx", "vy", "weight", "particles")
    exact = no_weight = close = 0
    first = None
    for c in sorted(set(ref) | set(got)):
        a, b = ref.get(c, []), got.get(c, [])
        e = len(a) == len(b) and all(all(x[k] == y[k] for k in keys) for x, y in zip(a, b))
        w = len(a) == len(b) and all(all(x[k] == y[k] for k in keys if k != "weight")
                                     for x, y in zip(a, b))
        n = len(a) == len(b) and all(
            abs(float(x["x"]) - float(y["x"])) < 0.1 and abs(float(x["y"]) - float(y["y"])) < 0.1
            and abs(float(x["vx"]) - float(y["vx"])) < 0.1
            and abs(float(x["vy"]) - float(y["vy"])) < 0.1 for x, y in zip(a, b))
        exact += e
        no_weight += w
        close += n
        if not w and first is None:
            first = c
    return len(set(ref) | set(got)), exact, no_weight, close, first


def reference_error(runs, export, trip):
    """Per (cycle, vehicle): the reference the filter was scored against vs SUMO's truth. The
    nuScenes export's instances carry the SUMO id (dualgrid_name); RadarScenes' track_id is it."""
    name = None
    if export:
        with open(os.path.join(export, "v1.0-mini", "instance.json")) as f:
            name = {r["token"]: r["dualgrid_name"] for r in json.load(f)}
    truth = {}
    with open(os.path.join(runs, "ground_truth.csv")) as f:
        for r in csv.DictReader(f):
            truth[(r["step"], r["id"])] = r
    dv, dx = [], []
    with open(os.path.join(trip, "ground_truth.csv")) as f:
        for r in csv.DictReader(f):
            t = truth.get((r["step"], name.get(r["id"], "") if name else r["id"]))
            if t is None:
                continue
            dv.append(((float(r["vx"]) - float(t["vx"])) ** 2 +
                       (float(r["vy"]) - float(t["vy"])) ** 2) ** 0.5)
            dx.append(((float(r["x"]) - float(t["x"])) ** 2 +
                       (float(r["y"]) - float(t["y"])) ** 2) ** 0.5)
    dv.sort()
    dx.sort()
    if not dv:
        return "no pairs"
    return (f"{len(dv)} pairs: |dv| mean {sum(dv) / len(dv):.3f} m/s, p95 "
            f"{dv[int(0.95 * len(dv))]:.3f}, max {dv[-1]:.3f}; |dx| mean {sum(dx) / len(dx):.3f} m, "
            f"max {dx[-1]:.3f}")


def metrics(path):
    with open(os.path.join(path, "metrics.json")) as f:
        m = json.load(f)["modes"]
    return {k: (v["tracked_fraction"], v["tracked_fraction_v"]) for k, v in m.items()}


def main():
    binary, network_dir, duration = sys.argv[1:4]
    work = tempfile.mkdtemp(prefix="dualgrid_nsrt.")
    for scenario in sys.argv[4:]:
        tag = os.path.splitext(os.path.basename(scenario))[0]
        runs = os.path.join(work, tag)
        run(binary, "run", scenario, "--duration", duration, "--network-dir", network_dir,
            "--detections", "exact", "--no-figures", "-q", "--out", runs)
        print(f"## {tag}, {duration} s: run D/D_v {metrics(runs)}")
        for kind, extra in (("float32", []), ("float64", ["--pcd-float64"])):
            ex = os.path.join(work, f"{tag}_{kind}")
            run(binary, "export", runs, "--format", "nuscenes", "--out", ex, "-q", *extra)
            trip = ex + "_trip"
            run(binary, "filter", ex, "--scene", "scene-0001", "--no-figures", "-q", "--out", trip)
            n, exact, no_w, close, first = agreement(cycles(os.path.join(runs, "clusters.csv")),
                                                    cycles(os.path.join(trip, "clusters.csv")))
            print(f"{kind}: {n} cycles x modes; identical {exact}, identical but the weight "
                  f"{no_w}, within 0.1 m and 0.1 m/s {close}; first differing {first}; "
                  f"D/D_v {metrics(trip)}")
            if kind == "float64":
                print(f"nuScenes references (annotations) vs SUMO's truth: "
                      f"{reference_error(runs, ex, trip)}")
        rs = os.path.join(work, f"{tag}_rs")
        run(binary, "export", runs, "--format", "radarscenes", "--out", rs, "-q")
        run(binary, "filter", os.path.join(rs, "data", "sequence_1"), "--no-figures", "-q",
            "--out", rs + "_trip")
        print(f"RadarScenes references (estimated from labelled points) vs SUMO's truth: "
              f"{reference_error(runs, None, rs + '_trip')}; D/D_v {metrics(rs + '_trip')}")
    subprocess.run(["rm", "-rf", work])


if __name__ == "__main__":
    main()
