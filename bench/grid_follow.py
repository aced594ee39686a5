#!/usr/bin/env python3
"""Does the grid keep the road ahead? For every step of a dualgrid run folder, the point the ego
will reach after driving AHEAD metres further along its own path (ground_truth.csv; past the end
of the run, straight on along its last heading) is tested against the grid's footprint of that
step (grid.csv). Prints the share of steps with the point inside the grid.

    bench/grid_follow.py RUN_DIR [--ahead 40] [--after T] [--min-share S]

--after T counts only steps at or after T seconds (after a turn); --min-share S exits 1 when the
share is below S (a check for ctest). Standard library only.
"""
import argparse
import bisect
import csv
import math
import pathlib
import sys


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dir", type=pathlib.Path)
    ap.add_argument("--ahead", type=float, default=40.0, help="distance ahead along the path [m]")
    ap.add_argument("--after", type=float, default=-math.inf, help="count steps from this time [s]")
    ap.add_argument("--min-share", type=float, default=None)
    a = ap.parse_args()
    ego = [r for r in read_rows(a.run_dir / "ground_truth.csv") if r["is_ego"] == "1"]
    grid = {r["step"]: r for r in read_rows(a.run_dir / "grid.csv")}
    if not ego or not grid:
        sys.exit(f"{a.run_dir}: no ego rows in ground_truth.csv or no rows in grid.csv")
    xs = [float(r["x"]) for r in ego]
    ys = [float(r["y"]) for r in ego]
    s = [0.0]
    for k in range(1, len(ego)):
        s.append(s[-1] + math.hypot(xs[k] - xs[k - 1], ys[k] - ys[k - 1]))
    last_yaw = float(ego[-1]["yaw"])

    def point_at(arc):
        if arc >= s[-1]:  # beyond the run: straight on
            d = arc - s[-1]
            return xs[-1] + d * math.cos(last_yaw), ys[-1] + d * math.sin(last_yaw)
        k = max(1, bisect.bisect_right(s, arc))
        seg = s[k] - s[k - 1]
        u = 0.0 if seg == 0 else (arc - s[k - 1]) / seg
        return xs[k - 1] + u * (xs[k] - xs[k - 1]), ys[k - 1] + u * (ys[k] - ys[k - 1])

    inside = counted = 0
    for k, r in enumerate(ego):
        if float(r["time"]) < a.after or r["step"] not in grid:
            continue
        g = grid[r["step"]]
        px, py = point_at(s[k] + a.ahead)
        yaw = math.radians(float(g["yaw_deg"]))
        dx, dy = px - float(g["x"]), py - float(g["y"])
        lx = math.cos(yaw) * dx + math.sin(yaw) * dy
        ly = -math.sin(yaw) * dx + math.cos(yaw) * dy
        counted += 1
        inside += abs(lx) <= 0.5 * float(g["length"]) and abs(ly) <= 0.5 * float(g["width"])
    share = inside / counted if counted else 0.0
    turns = sum(g["realigned"] == "1" for g in grid.values())
    print(f"{a.run_dir}: the point {a.ahead:g} m ahead on the ego's path is in the grid in "
          f"{inside} of {counted} steps ({100 * share:.1f} %); the grid turned {turns} times")
    if a.min_share is not None and share < a.min_share:
        sys.exit(1)


if __name__ == "__main__":
    main()
