#!/usr/bin/env bash
# CMake finds libsumo without SUMO's CMake config (which ships in sumo-tools, a package a minimal
# install may lack), and without libsumo at all says in one line which package to install.
# Usage: cmake_sumo_fallback.sh SOURCE_DIR
set -uo pipefail
src=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_cmake_fallback.XXXXXX")
trap 'rm -rf "$work"' EXIT
common=(-DDUALGRID_BUILD_TESTS=OFF -DDUALGRID_BUILD_BENCHMARKS=OFF -DCMAKE_DISABLE_FIND_PACKAGE_SUMO=ON)
out=$(cmake -S "$src" -B "$work/a" "${common[@]}" 2>&1)
if [ $? -ne 0 ] || [[ "$out" != *"SUMO's CMake config not found (package sumo-tools); using "*libsumocpp* ]]; then
  echo "FAIL: without SUMO's CMake config, configure should find libsumo directly:"; echo "$out"
  echo "cmake fallback: 0 passed, 1 failed"; exit 1
fi
# Hide libsumo's header and library too: the error must name the package.
libdir=$(dirname "$(find /usr/lib -name 'libsumocpp.so' -print -quit)")
out=$(cmake -S "$src" -B "$work/b" "${common[@]}" -DCMAKE_IGNORE_PATH="/usr/include;$libdir" 2>&1)
if [ $? -eq 0 ] || [[ "$out" != *"libsumo not found"* ]] || [[ "$out" != *"package 'sumo'"* ]]; then
  echo "FAIL: without libsumo, configure should fail naming the package:"; echo "$out"
  echo "cmake fallback: 1 passed, 1 failed"; exit 1
fi
echo "cmake fallback: 2 passed, 0 failed"
