#!/usr/bin/env bash
# test_slurm.sh -- docs/scale.md's Slurm job array, run as the page gives
# it, on a one-node Slurm of its own: munged with a key made here,
# slurmctld and slurmd (Debian slurm-wlm) with a minimal slurm.conf in a
# temporary folder, all in a network namespace of their own that has only
# the loopback interface (unshare -n), so nothing is bound or sent beyond
# 127.0.0.1. The shell block under "### Slurm job array" is read from
# docs/scale.md and run with /shared replaced by the test's folder and the
# tile size and bound of a 513^2 fractal (16 tiles); then:
#   - every array task and the merge job completed, 16 pieces were written;
#   - the merged layers equal `simplify -tile_size` with the same options
#     (md5 of ogrinfo);
#   - the page's rerun claim: with one piece removed the merge job fails
#     naming it and writes nothing; that task rerun alone (--array=K) and
#     the merge again give the same layers.
# Skips (77) unless root (slurmd runs the jobs as their user), with
# slurm-wlm, munge, unshare and ip present. Every daemon and job is killed
# on every exit path (the EXIT trap kills each process of the namespace by
# pid); the whole test is bounded by `timeout` (300 s).
set -u
. "$(dirname "${BASH_SOURCE[0]}")/../apps/tt_check.sh" || exit 1

T=${TT_TERRATIN:-}
if [ -z "$T" ] || [ ! -x "$T" ]; then
  echo "SKIP: TT_TERRATIN is not set or not executable"
  exit 77
fi
T=$(cd "$(dirname "$T")" && pwd)/$(basename "$T")
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
SELF="$HERE/tests/apps/test_slurm.sh"

if [ "${TT_SLURM_NETNS:-}" != 1 ]; then
  for tool in slurmctld slurmd sbatch scontrol scancel munged mungekey unshare ip timeout ogrinfo; do
    if ! command -v "$tool" >/dev/null 2>&1; then
      echo "SKIP: $tool is missing (Debian: apt-get install slurm-wlm munge iproute2)"
      exit 77
    fi
  done
  if [ "$(id -u)" != 0 ]; then
    echo "SKIP: not root (a one-node Slurm here runs slurmd as root)"
    exit 77
  fi
  if ! unshare -n true 2>/dev/null; then
    echo "SKIP: unshare -n is not permitted here (no network namespace)"
    exit 77
  fi
  export TT_SLURM_NETNS=1 TT_TERRATIN="$T"
  exec timeout -k 10 300 unshare -n -- bash "$SELF"
fi

# --- inside the namespace: only lo, brought up here. Slurm binds its ports
# through getaddrinfo(NULL, AI_PASSIVE | AI_ADDRCONFIG), which finds nothing
# when 127.0.0.1 is the only IPv4 address (glibc counts any other one as
# configured): a second loopback address, 127.0.0.2 on lo, lets it bind.
ip link set lo up && ip addr add 127.0.0.2/8 dev lo ||
  { echo "FAIL: ip link set lo up / ip addr add 127.0.0.2/8 dev lo" >&2; exit 1; }
NETNS=$(readlink /proc/$$/ns/net)
# the cleanup kills every process of this namespace: make sure it is not
# the machine's
if [ -z "$NETNS" ] || [ "$NETNS" = "$(readlink /proc/1/ns/net)" ] ||
   [ "$NETNS" = "$(readlink /proc/$PPID/ns/net 2>/dev/null)" ]; then
  echo "FAIL: not in a network namespace of its own (${NETNS:-unknown})" >&2
  exit 1
fi

W=$(mktemp -d "${TMPDIR:-/tmp}/tt_slurm.XXXXXX") || exit 1
chmod 700 "$W"
# every process of this namespace but this shell: the daemons, the jobs'
# slurmstepd and their children (the namespace is ours alone)
ns_pids() {
  local p
  for p in /proc/[0-9]*; do
    p=${p#/proc/}
    [ "$p" = $$ ] && continue
    [ "$(readlink /proc/$p/ns/net 2>/dev/null)" = "$NETNS" ] && echo "$p"
  done
}
cleanup() {
  local i p left
  export SLURM_CONF="$W/slurm.conf"
  timeout 5 scancel --quiet --full --user=root >/dev/null 2>&1
  for p in $(ns_pids); do kill -TERM "$p" 2>/dev/null; done
  for i in $(seq 1 20); do
    left=$(ns_pids)
    [ -z "$left" ] && break
    sleep 0.5
  done
  for p in $(ns_pids); do kill -KILL "$p" 2>/dev/null; done
  cd / && rm -rf "$W"
}
trap cleanup EXIT
trap 'exit 1' INT TERM HUP
cd "$W" || exit 1
mkdir -p munge ctld slurmd shared

# --- munge: a key made here, a socket in the folder
mungekey -c -k munge/munge.key >/dev/null 2>&1 || { echo "FAIL: mungekey" >&2; exit 1; }
chmod 600 munge/munge.key
munged -F --force --key-file="$W/munge/munge.key" --socket="$W/munge/munge.socket" \
  --pid-file="$W/munge/munged.pid" --log-file="$W/munge/munged.log" \
  --seed-file="$W/munge/munged.seed" >munge/out.log 2>&1 &
for i in $(seq 1 40); do [ -S munge/munge.socket ] && break; sleep 0.25; done
check "munged: up" [ -S munge/munge.socket ]

# --- slurm: one node of 2 CPUs named tt1 at 127.0.0.1; the controller is
# this host (slurmctld wants its own short host name), reached at 127.0.0.1
cat >slurm.conf <<EOF
ClusterName=ttslurm
SlurmctldHost=$(hostname -s)(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$W/munge/munge.socket
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
ReturnToService=2
MpiDefault=none
StateSaveLocation=$W/ctld
SlurmdSpoolDir=$W/slurmd
SlurmctldPidFile=$W/ctld/slurmctld.pid
SlurmdPidFile=$W/slurmd/slurmd.pid
SlurmctldLogFile=$W/ctld/slurmctld.log
SlurmdLogFile=$W/slurmd/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
NodeName=tt1 NodeAddr=127.0.0.1 NodeHostname=$(hostname -s) CPUs=2 RealMemory=16384 State=UNKNOWN
PartitionName=tt Nodes=tt1 Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$W/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" >ctld/out.log 2>&1 &
slurmd -D -N tt1 -f "$SLURM_CONF" >slurmd/out.log 2>&1 &
idle=0
t0=$SECONDS
while [ $((SECONDS - t0)) -lt 60 ]; do
  if timeout 5 sinfo -h -n tt1 -o %t 2>/dev/null | grep -q '^idle'; then idle=1; break; fi
  sleep 0.5
done
check "slurm: node tt1 idle" [ $idle = 1 ]
if [ $idle != 1 ]; then
  tail -5 ctld/slurmctld.log slurmd/slurmd.log munge/munged.log >&2
  echo "$passed passed, $failed failed"
  exit 1
fi

# --- the page's block, /shared being this folder's shared/
"$T" generate diamond_square shared/DEM.tif -size 513 -seed 5 -q || exit 1
awk '/^### Slurm job array/ { on = 1 } on && /^```sh/ { code = 1; next }
     code && /^```/ { exit } code { print }' "$HERE/docs/scale.md" >block.sh
check "docs/scale.md: the Slurm block found" grep -q 'sbatch --parsable --array' block.sh
sed -e "s#/shared/#$W/shared/#g" -e 's/-max_error 2 -tile_size 2048/-max_error 6 -tile_size 128/' \
  block.sh >job.sh
check "docs/scale.md: the block's plan options replaced" grep -q -- '-max_error 6 -tile_size 128' job.sh
cat job.sh
PATH="$(dirname "$T"):$PATH" bash -e job.sh >job.out 2>job.err
rc=$?
cat job.out job.err
check "the block: exit 0" [ $rc -eq 0 ]
ARRAY=$(scontrol show job 2>/dev/null | sed -n 's/^JobId=\([0-9]*\) ArrayJobId=\([0-9]*\) ArrayTaskId=.*/\2/p' | sort -u | head -1)
MERGE=$(sed -n 's/^Submitted batch job \([0-9]*\)$/\1/p' job.out | tail -1)

# wait_job ID: until no task of job ID is pending or running (120 s)
wait_job() {
  local i
  for i in $(seq 1 240); do
    scontrol show job "$1" 2>/dev/null | grep -q 'JobState=\(PENDING\|RUNNING\|CONFIGURING\|COMPLETING\)' || return 0
    sleep 0.5
  done
  return 1
}
states() { scontrol show job "$1" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | sort | uniq -c | tr -s ' ' | tr '\n' ';'; }
check "merge job submitted (${MERGE:-none}), array ${ARRAY:-none}" eval '[ -n "$MERGE" ] && [ -n "$ARRAY" ]'
check "merge job finished within 120 s" wait_job "${MERGE:-0}"
echo "array job $ARRAY: $(states "$ARRAY")  merge job $MERGE: $(states "$MERGE")"
check "16 array tasks completed" [ "$(states "$ARRAY")" = " 16 COMPLETED;" ]
check "merge job completed" [ "$(states "$MERGE")" = " 1 COMPLETED;" ]
check "16 pieces" [ "$(ls shared/plan.json.tiles 2>/dev/null | grep -c '^[0-9]*\.ttp$')" -eq 16 ]
dump() { ogrinfo -ro -al -q "$1" triangles vertices 2>/dev/null | md5sum | cut -d' ' -f1; }
"$T" simplify -q -max_error 6 -tile_size 128 shared/DEM.tif s.gpkg
check "merged layers = simplify -tile_size" eval '[ -s shared/tin.gpkg ] && [ "$(dump shared/tin.gpkg)" = "$(dump s.gpkg)" ]'

# --- a lost piece: the merge job fails naming it; that task alone rerun
rm -f shared/tin.gpkg shared/plan.json.tiles/7.ttp
out=$(PATH="$(dirname "$T"):$PATH" sbatch --parsable --wait --mem=16G \
  --wrap "terratin tiles merge $W/shared/plan.json $W/shared/tin.gpkg" 2>/dev/null)
rc=$?
check "merge with a piece missing: the job failed" [ $rc -ne 0 ]
check "... naming tile 7, nothing written" eval 'grep -q "missing (the first: .*/7\.ttp)" "slurm-$out.out" && [ ! -e shared/tin.gpkg ]'
cat "slurm-$out.out" 2>/dev/null
PATH="$(dirname "$T"):$PATH" sbatch --parsable --wait --array=7 --cpus-per-task=1 --mem=2G \
  --wrap "terratin tiles run $W/shared/plan.json \$SLURM_ARRAY_TASK_ID -overwrite" >/dev/null 2>&1
check "task 7 rerun alone" [ $? -eq 0 ]
PATH="$(dirname "$T"):$PATH" sbatch --parsable --wait --mem=16G \
  --wrap "terratin tiles merge $W/shared/plan.json $W/shared/tin.gpkg" >/dev/null 2>&1
check "merge again: exit 0" [ $? -eq 0 ]
check "merge again: the same layers" eval '[ -s shared/tin.gpkg ] && [ "$(dump shared/tin.gpkg)" = "$(dump s.gpkg)" ]'

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
