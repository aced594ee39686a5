#!/usr/bin/env bash
# ThreadSanitizer over the filter's OpenMP code: builds test_filter with clang, -fsanitize=thread
# and LLVM's OpenMP runtime in build-tsan/, and runs it with two threads under Archer
# (libarcher.so, LLVM's OpenMP tool that tells TSan about OpenMP's barriers, tasks and
# reductions). GCC's libgomp is not instrumented, so TSan on it reports every barrier as a race;
# with Archer a report is a real data race in our parallel regions. Installs clang, libomp-dev
# and clang's sanitizer runtimes if missing (Debian packages).
#   scripts/tsan.sh [TEST_FILTER ARGS...]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/install_missing.sh
install_missing clang libclang-rt-14-dev libomp-dev
archer=$(ls /usr/lib/llvm-*/lib/libarcher.so 2>/dev/null | sort -V | tail -n 1)
[ -n "$archer" ] || { echo "tsan.sh: libarcher.so not found (package libomp5-14)" >&2; exit 1; }
build=${DUALGRID_TSAN_BUILD_DIR:-build-tsan}
CXX=clang++ CC=clang cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DDUALGRID_SANITIZE=thread -DDUALGRID_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" --target test_filter
export OMP_TOOL_LIBRARIES=$archer OMP_NUM_THREADS=2
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 ignore_noninstrumented_modules=1"
export ARCHER_OPTIONS="verbose=1"
"$build/tests/filter/test_filter" --use-colour no "$@"
