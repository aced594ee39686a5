#!/usr/bin/env bash
# install_check.sh PREFIX CONSUMER_SRC WORK: the installed tree, moved elsewhere, used as a user
# would: a consumer project built with find_package(dualgrid), and the installed program run from
# another folder. Fails naming the step.
set -euo pipefail
prefix=$1 consumer=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
# Moved: nothing may point back into the prefix it was installed to (or into the build tree).
cp -a "$prefix" "$work/moved"
moved=$work/moved
fail() { echo "install_check: $*" >&2; exit 1; }

for f in bin/dualgrid libexec/dualgrid-bin lib/cmake/dualgrid/dualgridConfig.cmake share/dualgrid/networks/highway.net.xml \
         share/dualgrid/scenarios/highway.yaml include/dualgrid/cosim/cosimulation.hpp \
         include/dualgrid/filter/dynamic_grid.hpp; do
  [ -e "$moved/$f" ] || fail "missing in the installed tree: $f"
done

# 1. A consumer project against the moved tree.
cmake -S "$consumer" -B "$work/consumer-build" -DCMAKE_PREFIX_PATH="$moved" \
  -DCMAKE_BUILD_TYPE=Release >"$work/consumer-configure.log" 2>&1 ||
  { cat "$work/consumer-configure.log" >&2; fail "the consumer project did not configure"; }
cmake --build "$work/consumer-build" -j 2 >"$work/consumer-build.log" 2>&1 ||
  { tail -30 "$work/consumer-build.log" >&2; fail "the consumer project did not build"; }
out=$(env -u DUALGRID_NETWORK_DIR "$work/consumer-build/consumer") || fail "the consumer program failed: $out"
echo "$out"
grep -q "^filter ok$" <<<"$out" || fail "consumer: no 'filter ok'"
grep -q "^recorded ok$" <<<"$out" || fail "consumer: no 'recorded ok'"
grep -q "^networks=$moved/share/dualgrid/networks (package)$" <<<"$out" ||
  fail "consumer: sim::DefaultNetworkDir() is not the moved package's networks"
grep -q "^run folder ok$" <<<"$out" || fail "consumer: no 'run folder ok'"
grep -Eq "^steps=([1-9][0-9]*) of \1$" <<<"$out" || fail "consumer: the run did not reach its duration"
grep -Eq "^dual objects=[1-9][0-9]* matches=[1-9]" <<<"$out" || fail "consumer: dual scored nothing"
grep -q "$moved/share/dualgrid/networks" "$work/consumer-build/CMakeCache.txt" "$work/consumer-build/CMakeFiles/consumer.dir/flags.make" ||
  fail "consumer: dualgrid_NETWORK_DIR is not the moved tree's"

# 2. The installed program, from another folder, finds its own networks.
mkdir -p "$work/elsewhere"
cd "$work/elsewhere"
version=$(env -u DUALGRID_NETWORK_DIR "$moved/bin/dualgrid" --version)
echo "$version"
grep -q "networks: $moved/share/dualgrid/networks (installed)" <<<"$version" ||
  fail "--version does not name the moved tree's networks: $version"
env -u DUALGRID_NETWORK_DIR "$moved/bin/dualgrid" run "$moved/share/dualgrid/scenarios/highway.yaml" \
  --duration 2 --no-figures --modes dual --out run -q || fail "the installed program's run failed"
grep -q '"complete": true' run/summary.json || fail "the installed program's run is not complete"
echo "install_check: ok"
