#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (run as root, or with sudo available):
#   scripts/bootstrap.sh run   [SCENARIO]   install missing packages, build, run the default scenario
#   scripts/bootstrap.sh test               install missing packages, build, run the whole test suite
# Installs only Debian packages that are missing, so a second call skips apt entirely.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(build-essential cmake pkg-config sumo sumo-tools libeigen3-dev libyaml-cpp-dev catch2 libcli11-dev
  nlohmann-json3-dev librandom123-dev libbenchmark-dev libcairo2-dev libpng-dev zlib1g-dev
  parallel ffmpeg pybind11-dev python3-dev python3-numpy libexpat1-dev libhdf5-dev libhwy-dev)
# Only the test suite needs these: the replay viewer's browser test drives Debian's Chromium from
# Python's standard library (tests/viz/viewer_check.py); the Python module's tests hand its
# results to pandas (tests/python/test_run_scenario.py); the recorded-data tests write RadarScenes
# files with h5py, independently of our own writer (tests/recorded).
# Python tests: mypy (the stubs), matplotlib, nbconvert and ipykernel (the notebook), venv, pip,
# setuptools and wheel (pip install --no-build-isolation . into a venv).
TEST_PACKAGES=(chromium python3 python3-pandas python3-h5py mypy python3-matplotlib
               jupyter-nbconvert python3-ipykernel python3-venv python3-pip python3-setuptools
               python3-wheel)
BUILD_DIR=${DUALGRID_BUILD_DIR:-build}

source scripts/lib/install_missing.sh
if [ "${1:-run}" = test ]; then
  install_missing "${PACKAGES[@]}" "${TEST_PACKAGES[@]}"
else
  install_missing "${PACKAGES[@]}"
fi

# CI (CI=true, as .ci/run sets it) keeps the build warning-free: warnings are errors there.
werror=OFF
if [ "${CI:-}" = true ]; then werror=ON; fi
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DDUALGRID_WERROR=$werror >/dev/null
cmake --build "$BUILD_DIR" -j "$(nproc)"

case "${1:-run}" in
  run)
    scenario=${2:-scenarios/highway.yaml}
    # --video --viewer: the replay video and the interactive page beside the results.
    "$BUILD_DIR/tools/dualgrid" run "$scenario" --out "run/$(basename "$scenario" .yaml)" --force --video --viewer
    ;;
  test)
    ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)"
    ;;
  *)
    echo "usage: scripts/bootstrap.sh run [SCENARIO] | test" >&2
    exit 2
    ;;
esac
