#!/usr/bin/env python3
"""The tables of docs/results.md, "Multipath ghosts" (scripts/multipath_study.sh table).

Usage: multipath_table.py OUT SCENARIO...

Reads OUT/SCENARIO/multipath_{off,on}/seeds/seed_N/metrics.json (the study's experiments) and
OUT/rates/SCENARIO/seed_N/{detections.csv.gz,summary.json} (dualgrid sim with multipath on) and
prints Markdown: per scenario and weight mode the mean and 95 % confidence interval (Student t over
the seeds) of false clusters per scan, false dynamic cells per scan, D and D_v with multipath off
and on, and the paired difference on - off (the same seeds: with multipath on, every resolution
cell without a ghost draws what it drew with it off, so the pairs share most of their noise); then
the ghost rates per sensor. Standard library only.
"""
import csv
import gzip
import json
import math
import os
import sys

# Two-sided 95 % critical values of Student's t, df 1..30 (NIST/SEMATECH e-Handbook, 1.3.6.7.2),
# as eval::StudentT95.
T95 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
       2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
       2.052, 2.048, 2.045, 2.042]
MODES = ["position", "velocity", "dual"]


def summary(xs):
    """(n, mean, half width of the 95 % CI or None)."""
    n = len(xs)
    if n == 0:
        return 0, float("nan"), None
    mean = sum(xs) / n
    if n < 2:
        return n, mean, None
    sd = math.sqrt(sum((x - mean) ** 2 for x in xs) / (n - 1))
    t = T95[n - 2] if n - 1 <= len(T95) else 1.96
    return n, mean, t * sd / math.sqrt(n)


def fmt(s, scale=1.0, digits=2):
    n, mean, hw = s
    if n == 0:
        return "—"
    text = f"{mean * scale:.{digits}f}"
    return text + (f" ± {hw * scale:.{digits}f}" if hw is not None else "")


def false_dynamic_cells(mode):
    """Cells predicted dynamic whose truth is free or static, per scan (observed cells only)."""
    c = mode["cells"]
    confusion = c["confusion_truth_by_predicted"]
    dyn = c["confusion_columns"].index("dynamic")
    rows = c["confusion_rows"]
    wrong = confusion[rows.index("free")][dyn] + confusion[rows.index("static")][dyn]
    return wrong / c["frames"]


METRICS = [
    ("false clusters / scan", lambda m: m["false_clusters_per_scan"], 1.0, 2),
    ("false dynamic cells / scan", false_dynamic_cells, 1.0, 1),
    ("D [%]", lambda m: m["tracked_fraction"], 100.0, 1),
    ("D_v [%]", lambda m: m["tracked_fraction_v"], 100.0, 1),
]


def seed_metrics(folder):
    """{seed: metrics.json} of an experiment folder's finished seeds."""
    out = {}
    seeds = os.path.join(folder, "seeds")
    if not os.path.isdir(seeds):
        return out
    for name in sorted(os.listdir(seeds)):
        path = os.path.join(seeds, name, "metrics.json")
        if name.startswith("seed_") and os.path.isfile(path):
            with open(path) as f:
                out[int(name[5:])] = json.load(f)
    return out


def value(run, mode, metric):
    m = run["modes"].get(mode)
    if m is None:
        return None
    v = metric(m)
    return None if v is None else float(v)


def experiment_table(out, scenario):
    off = seed_metrics(os.path.join(out, scenario, "multipath_off"))
    on = seed_metrics(os.path.join(out, scenario, "multipath_on"))
    if not off and not on:
        return
    paired = sorted(set(off) & set(on))
    print(f"\n#### {scenario}: multipath off / on ({len(off)} / {len(on)} seeds; "
          f"paired differences over {len(paired)})\n")
    print("| metric | mode | off | on | on − off (paired) |")
    print("|---|---|---:|---:|---:|")
    for label, metric, scale, digits in METRICS:
        for mode in MODES:
            a = [v for v in (value(off[s], mode, metric) for s in sorted(off)) if v is not None]
            b = [v for v in (value(on[s], mode, metric) for s in sorted(on)) if v is not None]
            d = []
            for s in paired:
                x, y = value(off[s], mode, metric), value(on[s], mode, metric)
                if x is not None and y is not None:
                    d.append(y - x)
            print(f"| {label} | {mode} | {fmt(summary(a), scale, digits)} | "
                  f"{fmt(summary(b), scale, digits)} | {fmt(summary(d), scale, digits)} |")


def loss_table(out, scenario):
    """The scenario with multipath on at other rail losses (multipath_on_lossN), beside off."""
    base = os.path.join(out, scenario)
    runs = [("off", seed_metrics(os.path.join(base, "multipath_off")))]
    for name, label in (("multipath_on_loss0", "0 dB"), ("multipath_on", "6 dB (default)"),
                        ("multipath_on_loss12", "12 dB")):
        m = seed_metrics(os.path.join(base, name))
        if m:
            runs.append((label, m))
    if len(runs) < 3:
        return
    print(f"\n#### {scenario}: rail loss per bounce (multipath on; mean ± 95 % CI over seeds)\n")
    print("| metric | mode | " + " | ".join(label for label, _ in runs) + " |")
    print("|---|---|" + "---:|" * len(runs))
    for label, metric, scale, digits in METRICS:
        for mode in MODES:
            cells = []
            for _, run in runs:
                xs = [v for v in (value(run[s], mode, metric) for s in sorted(run)) if v is not None]
                cells.append(fmt(summary(xs), scale, digits))
            print(f"| {label} | {mode} | " + " | ".join(cells) + " |")


def rates_table(out, scenarios):
    rows = []
    for scenario in scenarios:
        folder = os.path.join(out, "rates", scenario)
        if not os.path.isdir(folder):
            continue
        per_sensor = {}  # sensor -> {kind: [per-seed rates]}
        seeds = 0
        for name in sorted(os.listdir(folder)):
            det = os.path.join(folder, name, "detections.csv.gz")
            summ = os.path.join(folder, name, "summary.json")
            if not (os.path.isfile(det) and os.path.isfile(summ)):
                continue
            with open(summ) as f:
                steps = json.load(f)["steps"]
            seeds += 1
            counts = {}
            with gzip.open(det, "rt") as f:
                for r in csv.DictReader(f):
                    c = counts.setdefault(r["sensor_name"], {"real": 0, "type1": 0, "type2_2": 0,
                                                             "type2_3": 0})
                    if r["path"] == "clutter":
                        continue
                    if r["path"] == "direct":
                        c["real"] += 1
                    elif r["path"] == "type1":
                        c["type1"] += 1
                    else:
                        c["type2_3" if r["bounces"] == "3" else "type2_2"] += 1
            for sensor, c in counts.items():
                ghosts = c["type1"] + c["type2_2"] + c["type2_3"]
                s = per_sensor.setdefault(sensor, {k: [] for k in
                                                   ("ghosts", "type1", "type2_2", "type2_3",
                                                    "share")})
                s["ghosts"].append(ghosts / steps)
                s["type1"].append(c["type1"] / steps)
                s["type2_2"].append(c["type2_2"] / steps)
                s["type2_3"].append(c["type2_3"] / steps)
                total = ghosts + c["real"]
                s["share"].append(ghosts / total if total else 0.0)
        for sensor in ["front_left", "front_right", "rear_left", "rear_right", "front"]:
            if sensor in per_sensor:
                s = per_sensor[sensor]
                rows.append(f"| {scenario} | {sensor} | {fmt(summary(s['ghosts']))} | "
                            f"{fmt(summary(s['type1']))} | {fmt(summary(s['type2_2']))} | "
                            f"{fmt(summary(s['type2_3']))} | "
                            f"{fmt(summary(s['share']), 100.0, 1)} | {seeds} |")
    if rows:
        print("\n#### Ghost rates per sensor (dualgrid sim, multipath on)\n")
        print("| scenario | sensor | ghosts / scan | type 1 (order 2) | type 2 (order 2) | "
              "type 2 (order 3) | ghosts among non-clutter detections [%] | seeds |")
        print("|---|---|---:|---:|---:|---:|---:|---:|")
        for r in rows:
            print(r)


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: multipath_table.py OUT SCENARIO...")
    out, scenarios = sys.argv[1], sys.argv[2:]
    for scenario in scenarios:
        experiment_table(out, scenario)
    for scenario in scenarios:
        loss_table(out, scenario)
    rates_table(out, scenarios)


if __name__ == "__main__":
    main()
