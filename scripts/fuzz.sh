#!/usr/bin/env bash
# Fuzzes the scenario loader, the regression-suite reader, the replay reader, the sweep readers
# (plan.json, table.json, summary.json) and the readers of recorded data (RadarScenes JSON, run
# folders, nuScenes tables and PCD) with libFuzzer, each for a bounded time (default 600 s):
#   scripts/fuzz.sh [SECONDS] [TARGET...]   (targets: scenario_loader suite_reader replay_reader
#                                            sweep_reader radarscenes_reader run_folder_reader
#                                            nuscenes_reader; default all)
# Installs clang and its libFuzzer runtime if missing (Debian packages), builds build-fuzz/ with
# clang, coverage instrumentation and ASan + UBSan, and runs the ctest label `fuzz`. A crash
# leaves its input in build-fuzz/tests/fuzz/TARGET-crash-*; make it a case of tests/hostile/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
source scripts/lib/install_missing.sh
install_missing clang libclang-rt-14-dev libomp-dev
build=${DUALGRID_FUZZ_BUILD_DIR:-build-fuzz}
CXX=clang++ CC=clang cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDUALGRID_FUZZ=ON \
  -DDUALGRID_SANITIZE=fuzzer-no-link,address,undefined -DDUALGRID_BUILD_TESTS=OFF \
  -DDUALGRID_BUILD_BENCHMARKS=OFF -DDUALGRID_FUZZ_SECONDS="$seconds" >/dev/null
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scenario_loader suite_reader replay_reader sweep_reader
                                     radarscenes_reader run_folder_reader nuscenes_reader)
for t in "${targets[@]}"; do
  cmake --build "$build" -j "$(nproc)" --target "fuzz_$t"
done
regex=$(IFS='|'; echo "^fuzz_(${targets[*]})\$")
ctest --test-dir "$build" -L fuzz -R "$regex" --output-on-failure
