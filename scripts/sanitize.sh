#!/usr/bin/env bash
# Builds the project with AddressSanitizer + UndefinedBehaviorSanitizer (our targets only, via
# -DDUALGRID_SANITIZE) in build-asan/ and runs the whole test suite under them. Any memory error,
# undefined behaviour or leak in our code fails it; leaks inside fontconfig and libsumo's
# xerces-c are suppressed (tests/sanitize/lsan.supp). Needs the packages of scripts/bootstrap.sh.
#   scripts/sanitize.sh [CTEST ARGS...]     e.g. scripts/sanitize.sh -R test_filter
set -euo pipefail
cd "$(dirname "$0")/.."
build=${DUALGRID_ASAN_BUILD_DIR:-build-asan}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDUALGRID_SANITIZE=address,undefined \
  -DDUALGRID_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j "$(nproc)"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS=suppressions=$PWD/tests/sanitize/lsan.supp:print_suppressions=0
# Sanitized runs are several times slower: one test at a time per core, generous timeouts.
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" --timeout 3600 "$@"
