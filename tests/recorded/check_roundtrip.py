#!/usr/bin/env python3
"""Round trip (issue 23): a simulated run recorded with --detections exact, exported as a
RadarScenes dataset root, filtered again: every cycle's clusters equal the run's (time, mode,
position, velocity, weight, particle count; role and object differ by design: the export's
objects are the tracks' estimated boxes). The run folder filtered directly gives them too.

Usage: check_roundtrip.py DUALGRID NETWORK_DIR SCENARIO DURATION
"""
import csv
import os
import subprocess
import sys
import tempfile

KEYS = ("time", "mode", "x", "y", "vx", "vy", "weight", "particles")


def run(*args):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"FAIL: {' '.join(args)} exited {r.returncode}: {r.stderr.strip()}")


def clusters(path):
    with open(path) as f:
        return [tuple(row[k] for k in KEYS) for row in csv.DictReader(f)]


def compare(name, ref, got):
    if len(ref) != len(got):
        return f"{name}: {len(got)} clusters, the run {len(ref)}"
    for i, (a, b) in enumerate(zip(ref, got)):
        if a != b:
            return f"{name}: cluster row {i + 2} differs: run {a}, {name} {b}"
    return None


def main():
    binary, network_dir, scenario, duration = sys.argv[1:5]
    work = tempfile.mkdtemp(prefix="dualgrid_roundtrip.", dir=os.environ.get("TMPDIR"))
    runs = os.path.join(work, "run")
    run(binary, "run", scenario, "--duration", duration, "--network-dir", network_dir,
        "--detections", "exact", "--no-figures", "-q", "--out", runs)
    root = os.path.join(work, "rs")
    run(binary, "export", runs, "--format", "radarscenes", "--out", root, "-q")
    for f in ("sensors.json", "sequences.json", "data/sequence_1/scenes.json",
              "data/sequence_1/radar_data.h5"):
        if not os.path.isfile(os.path.join(root, f)):
            sys.exit(f"FAIL: the export has no {f}")
    own = os.path.join(runs, "scenario.yaml")
    trip = os.path.join(work, "trip")
    run(binary, "filter", os.path.join(root, "data", "sequence_1"), "--scenario", own,
        "--no-figures", "-q", "--out", trip)
    direct = os.path.join(work, "direct")
    run(binary, "filter", runs, "--scenario", own, "--no-figures", "-q", "--out", direct)
    ref = clusters(os.path.join(runs, "clusters.csv"))
    if len(ref) < 50:
        sys.exit(f"FAIL: the run has only {len(ref)} clusters: nothing to compare")
    errors = [e for e in (compare("export", ref, clusters(os.path.join(trip, "clusters.csv"))),
                          compare("run folder", ref,
                                  clusters(os.path.join(direct, "clusters.csv")))) if e]
    if errors:
        sys.exit("FAIL: " + "; ".join(errors))
    print(f"round trip: {len(ref)} clusters equal in every cycle (export and run folder)")
    subprocess.run(["rm", "-rf", work])


if __name__ == "__main__":
    main()
