#!/usr/bin/env bash
# The Slurm path of `dualgrid sweep` on a single-node Slurm started on this machine (ctest
# sweep_slurm, label cluster). Opt-in: runs only with DUALGRID_CLUSTER=1 (it starts munged,
# slurmctld and slurmd as root and writes /etc/slurm/slurm.conf); skipped (exit 77) otherwise or
# when Slurm is not installed. usage: sweep_slurm.sh DUALGRID WORK_DIR SOURCE_DIR
set -uo pipefail
B=$1
WORK=$2
SRC=$3
if [[ ${DUALGRID_CLUSTER:-} != 1 ]]; then
  echo "skipped: opt-in, run with DUALGRID_CLUSTER=1 ctest -L cluster (starts a single-node Slurm as root)"
  exit 77
fi
if ! command -v sbatch >/dev/null || [[ ! -x /usr/sbin/slurmctld ]]; then
  echo "skipped: Slurm is not installed (apt-get install slurm-wlm munge)"
  exit 77
fi
rm -rf "$WORK" && mkdir -p "$WORK"
bash "$SRC/scripts/slurm_single_node.sh" start "$WORK/slurm-state" || exit 1
trap 'bash "$SRC/scripts/slurm_single_node.sh" stop "$WORK/slurm-state"' EXIT
AXES=(--set tangential.sensor=front --set tangential.angle=0:90:90 --set tangential.count=1)
"$B" sweep tangential "${AXES[@]}" --seeds 2 --duration 8 --out "$WORK/slurm" --emit slurm || exit 1
sbatch --wait "$WORK/slurm/slurm.sh" || { echo "FAILED: sbatch"; exit 1; }
"$B" collect "$WORK/slurm" || { echo "FAILED: collect"; exit 1; }
"$B" sweep tangential "${AXES[@]}" --seeds 2 --duration 8 -j 2 --out "$WORK/local" -q || exit 1
cmp "$WORK/slurm/aggregate.csv" "$WORK/local/aggregate.csv" ||
  { echo "FAILED: Slurm and local tables differ"; exit 1; }
echo "Slurm array of $(wc -l <"$WORK/slurm/runs.txt") tasks collected; tables identical to -j 2"
