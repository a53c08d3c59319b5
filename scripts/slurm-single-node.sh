#!/usr/bin/env bash
# slurm-single-node.sh: a one-node Slurm "cluster" on this machine (Debian 12's slurm-wlm and
# munge), to try `prsm serve --executor slurm` and scripts/prsm-study.sbatch for real
# (docs/mpi.md, "A single-node Slurm"). Not used by CI (tests/slurm_test.py has stand-ins).
#
#   sudo scripts/slurm-single-node.sh start    # install if missing, configure, start munged, slurmctld, slurmd
#   sudo scripts/slurm-single-node.sh status   # sinfo and squeue
#   sudo scripts/slurm-single-node.sh stop     # stop the three daemons this script started
#
# Needs root (the daemons, /etc/slurm, /etc/munge). It writes /etc/slurm/slurm.conf for one
# node (this host, every CPU, partition "debug"), without accounting (sacct then says so: the
# service's executor reads the job's exit code file instead) and without cgroups
# (proctrack/linuxproc, task/none), so it also runs in a container without systemd. An existing
# /etc/slurm/slurm.conf is kept as slurm.conf.orig. The daemons' logs: /var/log/slurm/.
set -euo pipefail

state=/run/prsm-slurm-single-node
mkdir -p "$state"

start() {
  if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge
  fi
  local host cpus mem_mb
  host=$(hostname -s)
  cpus=$(nproc)
  mem_mb=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 9 / 10 ))

  # munge: a key, then the daemon (as the munge user)
  if [ ! -s /etc/munge/munge.key ]; then
    if command -v mungekey >/dev/null; then mungekey --create --force; else
      dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none; fi
  fi
  chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
  mkdir -p /run/munge /var/log/munge /var/lib/munge
  chown munge:munge /run/munge /var/log/munge /var/lib/munge
  if ! pgrep -x munged >/dev/null; then
    runuser -u munge -- /usr/sbin/munged
    touch "$state/munged.started"   # stop ends it (its pid: /run/munge/munged.pid)
  fi
  munge -n | unmunge >/dev/null

  # slurm.conf for this one node
  mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
  if [ -f /etc/slurm/slurm.conf ] && ! grep -q "prsm single node" /etc/slurm/slurm.conf; then
    cp /etc/slurm/slurm.conf /etc/slurm/slurm.conf.orig
  fi
  cat > /etc/slurm/slurm.conf <<EOF
# prsm single node (scripts/slurm-single-node.sh)
ClusterName=prsm
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
ReturnToService=2
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
  pgrep -x slurmctld >/dev/null || slurmctld
  pgrep -x slurmd >/dev/null || slurmd
  for _ in $(seq 1 50); do
    if sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then
      echo "slurm-single-node: up: $(sinfo -h -o '%P %D %T %c' | head -1) (node $host)"
      return 0
    fi
    sleep 0.2
  done
  scontrol update nodename="$host" state=resume 2>/dev/null || true
  sinfo
}

stop() {
  for d in slurmd slurmctld; do
    [ -s "$state/$d.pid" ] && kill "$(cat "$state/$d.pid")" 2>/dev/null || true
  done
  if [ -e "$state/munged.started" ] && [ -s /run/munge/munged.pid ]; then
    kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
  fi
  rm -f "$state/munged.started"
  echo "slurm-single-node: stopped"
}

case "${1:-start}" in
  start) start ;;
  stop) stop ;;
  status) sinfo; squeue ;;
  *) echo "usage: $0 start|status|stop" >&2; exit 64 ;;
esac
