#!/usr/bin/env python3
"""nuScenes input (issue 40): a scene written by make_nuscenes.py (numpy + json from the public
schema, not through dualgrid's writer) is filtered by `dualgrid filter ROOT --scene NAME`.

Checks: the moving cars (lead, crossing) are tracked with the right velocity (D_v, and the mean
velocity of the clusters matched to each within 1 m/s of its true velocity: the scene's Doppler
noise is 0.05 m/s, so a correct filter lands well inside); the parked car, the pedestrian and the
car annotated once are no objects, and are counted as such; objects.csv names the instances by
token with their category; the devkit's default filter removes the invalid ghosts and
--invalid-states all keeps them; the scene's token selects the same scene as its name; the
point-level labels give point scores; the first step is 1 (as `run`'s).

Usage: check_nuscenes.py DUALGRID
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def run(*args):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"FAIL: {' '.join(args)} exited {r.returncode}: {r.stderr.strip()}")
    return r.stdout


def fail(msg):
    sys.exit("FAIL: " + msg)


def main():
    binary = sys.argv[1]
    work = tempfile.mkdtemp(prefix="dualgrid_nuscenes.", dir=os.environ.get("TMPDIR"))
    root = os.path.join(work, "nuscenes")
    truth = json.loads(run(sys.executable, os.path.join(HERE, "make_nuscenes.py"), "--out", root))
    out = os.path.join(work, "run")
    run(binary, "filter", root, "--scene", "scene-test", "--modes", "dual", "--no-figures", "-q",
        "--threads", "1", "--out", out)
    with open(os.path.join(out, "summary.json")) as f:
        inp = json.load(f)["input"]
    expect = {"kind": "nuscenes", "scene_token": "scene-1", "moving_instances": 2,
              "static_instances": 1, "skipped_instances": 1, "ego_velocity_estimated": True}
    for k, v in expect.items():
        if inp.get(k) != v:
            fail(f"summary.json input.{k} = {inp.get(k)}, expected {v}")
    if not inp["filtered_points"] > 0:
        fail("the devkit's default filter removed no invalid point")
    with open(os.path.join(out, "objects.csv")) as f:
        objects = {r["name"]: r for r in csv.DictReader(f)}
    if set(objects) != {"inst-lead", "inst-cross"}:
        fail(f"objects.csv holds {sorted(objects)}, expected the two moving cars")
    for name, o in objects.items():
        if o["category"] != "vehicle.car":
            fail(f"objects.csv: {name} has category {o['category']!r}")
        if not float(o["D_v"]) >= 0.8:
            fail(f"{name}: D_v {o['D_v']} < 0.8")
    # The clusters matched to each car: their mean velocity against the truth.
    with open(os.path.join(out, "clusters.csv")) as f:
        rows = list(csv.DictReader(f))
    if int(rows[0]["step"]) < 1:
        fail(f"clusters.csv starts at step {rows[0]['step']}: steps count from 1 as in `run`")
    for name in objects:
        m = [r for r in rows if r["object"] == name and r["role"] == "matched"]
        if len(m) < 100:
            fail(f"{name}: only {len(m)} matched clusters")
        vx = sum(float(r["vx"]) for r in m) / len(m)
        vy = sum(float(r["vy"]) for r in m) / len(m)
        tv = truth[name]["velocity"]
        err = math.hypot(vx - tv[0], vy - tv[1])
        if err > 1.0:
            fail(f"{name}: mean cluster velocity ({vx:.2f}, {vy:.2f}), truth {tv}: {err:.2f} m/s")
        print(f"{name}: {len(m)} matched clusters, mean velocity error {err:.3f} m/s, "
              f"D_v {objects[name]['D_v']}")
    with open(os.path.join(out, "metrics.json")) as f:
        points = json.load(f)["modes"]["dual"]["points"]
    if not (points["true_positives"] > 0 and points["f1"] > 0.8):
        fail(f"point-level scores {points}")
    # The scene's token selects the same scene; --invalid-states all keeps the ghosts.
    by_token = os.path.join(work, "by_token")
    run(binary, "filter", root, "--scene", "scene-1", "--modes", "dual", "--no-figures", "-q",
        "--threads", "1", "--out", by_token)
    with open(os.path.join(by_token, "clusters.csv")) as f:
        if list(csv.DictReader(f)) != rows:
            fail("--scene by token gave other clusters than by name")
    all_states = os.path.join(work, "all_states")
    run(binary, "filter", root, "--scene", "scene-test", "--modes", "dual", "--no-figures", "-q",
        "--threads", "1", "--invalid-states", "all", "--out", all_states)
    with open(os.path.join(all_states, "summary.json")) as f:
        inp_all = json.load(f)["input"]
    if inp_all["filtered_points"] != 0 or \
            inp_all["detections"] != inp["detections"] + inp["filtered_points"]:
        fail(f"--invalid-states all: {inp_all['filtered_points']} filtered, "
             f"{inp_all['detections']} detections (default: {inp['detections']} + "
             f"{inp['filtered_points']})")
    print(f"nuScenes scene: {inp['detections']} detections, {inp['filtered_points']} invalid "
          f"removed, point F1 {points['f1']:.3f}")
    subprocess.run(["rm", "-rf", work])


if __name__ == "__main__":
    main()
