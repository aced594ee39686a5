#!/usr/bin/env python3
"""Alternating rounds of bench_filter benchmarks in two builds: wall and thread 0's CPU time.

  bench/paired_cycle.py ROUNDS OLD_BUILD NEW_BUILD FILTER [FILTER ...] [--reps N] [--min-time S]

Each round runs every FILTER (a --benchmark_filter regex matching ONE benchmark, e.g.
'BM_PaperConfig/10000/2/') in OLD then NEW, each with N repetitions (default 3), and keeps the
median of the repetitions' real_time (wall) and cpu_time (Google Benchmark's CPU time: the
benchmark thread's, i.e. thread 0 of the filter's team). Prints per benchmark the per-round
values [us], the medians over the rounds and the median of the per-round ratios NEW / OLD (the
figure to quote on a loaded machine). The environment passes through: set OMP_NUM_THREADS to the
benchmark's thread count and OMP_WAIT_POLICY=PASSIVE GOMP_SPINCOUNT=300 as `dualgrid` does.
Exit codes: 0 done, 2 bad arguments or a benchmark that printed nothing.
"""
import json
import os
import statistics as st
import subprocess
import sys


def run(build, flt, reps, min_time):
    exe = os.path.join(build, "bench", "bench_filter")
    cmd = [exe, f"--benchmark_filter={flt}", f"--benchmark_repetitions={reps}",
           "--benchmark_format=json", "--benchmark_time_unit=us"]
    if min_time:
        cmd.append(f"--benchmark_min_time={min_time}")
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    try:
        rows = [b for b in json.loads(out.stdout)["benchmarks"] if b.get("run_type") == "iteration"]
    except (json.JSONDecodeError, KeyError):
        rows = []
    if not rows:
        sys.exit(f"paired_cycle.py: {exe} printed no result for '{flt}'")
    scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}
    real = [r["real_time"] * scale[r["time_unit"]] for r in rows]
    cpu = [r["cpu_time"] * scale[r["time_unit"]] for r in rows]
    return st.median(real), st.median(cpu)


def main(argv):
    reps, min_time, args = 3, None, []
    it = iter(argv)
    for a in it:
        if a == "--reps":
            reps = int(next(it))
        elif a == "--min-time":
            min_time = next(it)
        else:
            args.append(a)
    if len(args) < 4 or not args[0].isdigit() or int(args[0]) < 1:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    rounds, old, new, filters = int(args[0]), args[1], args[2], args[3:]
    res = {f: [] for f in filters}
    for _ in range(rounds):
        for f in filters:
            res[f].append((run(old, f, reps, min_time), run(new, f, reps, min_time)))
    for f in filters:
        print(f"{f}  (rounds: old real/cpu, new real/cpu [us])")
        for (orl, ocp), (nrl, ncp) in res[f]:
            print(f"  {orl:10.1f} {ocp:10.1f}   {nrl:10.1f} {ncp:10.1f}")
        col = lambda k, j: [r[k][j] for r in res[f]]
        for j, name in ((0, "real"), (1, "cpu ")):
            o, n = col(0, j), col(1, j)
            ratio = st.median([b / a for a, b in zip(o, n)])
            print(f"  {name}: old median {st.median(o):.1f} [{min(o):.1f}-{max(o):.1f}], new median "
                  f"{st.median(n):.1f} [{min(n):.1f}-{max(n):.1f}], median ratio new/old {ratio:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
