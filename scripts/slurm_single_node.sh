#!/usr/bin/env bash
# A single-node Slurm on this machine, for testing `dualgrid sweep --emit slurm` (docs/stress.md).
# Needs the Debian packages slurm-wlm and munge (apt-get install slurm-wlm munge) and root.
#   scripts/slurm_single_node.sh start [STATE_DIR]   start munged, slurmctld, slurmd; wait for idle
#   scripts/slurm_single_node.sh stop  [STATE_DIR]   stop the daemons started by `start`
# No systemd, no cgroups, no slurm user: the settings of ../shared/notes-style single-node setups.
set -euo pipefail
ACTION=${1:?usage: slurm_single_node.sh start|stop [STATE_DIR]}
STATE=${2:-/tmp/dualgrid-slurm}
CONF=/etc/slurm/slurm.conf

stop() {
  for pid in "$STATE"/slurmd.pid "$STATE"/slurmctld.pid; do
    [[ -f $pid ]] && kill "$(cat "$pid")" 2>/dev/null || true
  done
  sleep 1
}

case $ACTION in
  stop) stop; exit 0 ;;
  start) ;;
  *) echo "slurm_single_node.sh: unknown action '$ACTION'" >&2; exit 2 ;;
esac

for exe in slurmctld slurmd munged sbatch; do
  command -v "$exe" >/dev/null || [[ -x /usr/sbin/$exe ]] ||
    { echo "slurm_single_node.sh: $exe not found (apt-get install slurm-wlm munge)" >&2; exit 3; }
done
mkdir -p "$STATE"/spool/ctld "$STATE"/spool/d "$STATE"/log /etc/slurm
# munge: its key comes with the package; the daemon runs as its own user.
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  [[ -f /etc/munge/munge.key ]] || { mkdir -p /etc/munge; dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 2>/dev/null; chown munge:munge /etc/munge/munge.key; chmod 400 /etc/munge/munge.key; }
  mkdir -p /run/munge && chown munge:munge /run/munge
  su -s /bin/sh munge -c /usr/sbin/munged
  sleep 1
fi
munge -n | unmunge | grep -q 'STATUS: *Success' || { echo "munge does not work" >&2; exit 3; }

HOST=$(hostname -s)
CPUS=$(nproc)
MEM=$(awk '/MemTotal/ {print int($2 / 1024 * 0.8)}' /proc/meminfo)
cat >"$CONF" <<CONF
ClusterName=dualgrid
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
StateSaveLocation=$STATE/spool/ctld
SlurmdSpoolDir=$STATE/spool/d
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/log/slurmctld.log
SlurmdLogFile=$STATE/log/slurmd.log
ReturnToService=2
MpiDefault=none
NodeName=$HOST CPUs=$CPUS RealMemory=$MEM State=UNKNOWN
PartitionName=main Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
stop
/usr/sbin/slurmctld
/usr/sbin/slurmd
for _ in $(seq 1 30); do
  if sinfo -h -o '%t' 2>/dev/null | grep -qE 'idle|mix'; then
    echo "slurm: node $HOST idle ($CPUS CPUs, ${MEM} MB)"
    exit 0
  fi
  sleep 1
done
echo "slurm: the node did not become idle in 30 s (logs: $STATE/log)" >&2
exit 1
