#!/usr/bin/env bash
# A single weight mode's results do not depend on the likelihood of the weight it does not
# resample on (docs/algorithm.md, "Float state"): the position mode gives the same clusters,
# objects and grid whatever filter.velocity_likelihood says, with the per-cell normalisation
# (Doppler births) and with the paper preset's literal one. The highway, seed 4: there the vector
# likelihood drives some cells' velocity-weight factor out of float's range (after ~40 s), which
# the float cycle of 2026-11-27 09:30 let change the position mode's bits (the check can fail).
# Usage: mode_independence.sh DUALGRID REPO
set -euo pipefail
dualgrid=$1
repo=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/dualgrid_mode_independence.XXXXXX")
trap 'rm -rf "$work"' EXIT
status=0
# run NAME ARGS...: the position mode alone on the highway, seed 4.
run() {
  local name=$1
  shift
  "$dualgrid" run "$repo/scenarios/highway.yaml" --modes position --seed 4 --no-figures -q \
    --out "$work/$name" "$@"
}
# same A B: the run folders' results agree byte for byte.
same() {
  for f in clusters.csv objects.csv grid.csv; do
    if ! cmp -s "$work/$1/$f" "$work/$2/$f"; then
      echo "FAIL: position mode, $1 and $2 differ in $f"
      status=1
    fi
  done
}
for l in vector radial radial_fit; do
  run "percell_$l" --set filter.birth_velocity=doppler --set filter.velocity_likelihood=$l
done
same percell_vector percell_radial
same percell_vector percell_radial_fit
for l in vector radial; do
  run "paper_$l" --set filter.preset=paper --set filter.velocity_likelihood=$l
done
same paper_vector paper_radial
[[ $status -eq 0 ]] && echo "position mode: the same results for every velocity likelihood"
exit $status
