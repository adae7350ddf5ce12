#!/usr/bin/env bash
# A real render-farm run on this machine: installs Slurm and MUNGE (Debian's
# slurm-wlm and munge) when missing, starts a one-node cluster in a
# temporary directory (munged, slurmctld, slurmd in the foreground, no
# systemd), submits the showcase as a 72-frame turntable in a job array of
# 4 shards with the recipe of docs/workflow.md (scripts/slurm-array.sh),
# waits, checks the shards' files are byte-identical to one process's
# render, stops the daemons it started. Exit 0 on success, 1 otherwise.
#
#   bash scripts/slurm-smoke.sh [SOFTRASTER_BINARY]
#
# Without an argument it builds and uses target/debug/softraster (the test
# profile is optimized).
set -uo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

say() { echo "slurm-smoke: $*"; }
fail() { say "FAIL: $*"; exit 1; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    say "installing slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    (apt-get install -y -qq slurm-wlm munge >/dev/null 2>&1 \
        || (apt-get update -qq && apt-get install -y -qq slurm-wlm munge >/dev/null)) \
        || fail "cannot install slurm-wlm and munge"
fi

bin=${1:-}
if [ -z "$bin" ]; then
    cargo build --quiet --bin softraster || fail "cargo build"
    bin=$repo/target/debug/softraster
fi
bin=$(realpath "$bin")

tmp=$(mktemp -d /tmp/slurm-smoke.XXXXXX)
# munged refuses a socket directory that is not world-executable.
chmod 755 "$tmp"
mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/log" "$tmp/shards" "$tmp/single"
chmod 755 "$tmp/munge"
pids=()

stop() {
    # slurmd last, once the job steps' sockets in its spool are gone.
    if [ -n "${SLURM_CONF:-}" ]; then
        scancel --quiet --user="$(id -un)" 2>/dev/null || true
    fi
    for _ in $(seq 1 50); do
        ls "$tmp"/spool/*_*.* >/dev/null 2>&1 || break
        sleep 0.1
    done
    for p in "${pids[@]}"; do
        kill "$p" 2>/dev/null
    done
    for p in "${pids[@]}"; do
        wait "$p" 2>/dev/null
    done
    rm -rf "$tmp"
}
trap stop EXIT

# MUNGE with a private key and socket.
dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$tmp/munge/munge.key"
socket=$tmp/munge/munge.socket
munged --foreground --force --key-file="$tmp/munge/munge.key" --socket="$socket" \
    --pid-file="$tmp/munge/munged.pid" --seed-file="$tmp/munge/munged.seed" \
    --log-file="$tmp/log/munged.log" >>"$tmp/log/munged.out" 2>&1 &
pids+=($!)
for _ in $(seq 1 50); do [ -S "$socket" ] && break; sleep 0.1; done
[ -S "$socket" ] || fail "munged did not start: $(cat "$tmp/log/munged.log" 2>/dev/null)"

# One node, addressed by IP so nothing depends on name resolution; the
# controller's name must be this host's.
host=$(hostname -s)
node=smoke
cpus=$(nproc)
user=$(id -un)
cat > "$tmp/slurm.conf" <<EOF
ClusterName=smoke
SlurmctldHost=$host(127.0.0.1)
MailProg=/bin/true
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
SlurmUser=$user
SlurmdUser=root
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerParameters=batch_sched_delay=0
ReturnToService=2
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=main Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$tmp/slurm.conf

slurmctld -D -i -f "$SLURM_CONF" >>"$tmp/log/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N "$node" -f "$SLURM_CONF" >>"$tmp/log/slurmd.out" 2>&1 &
pids+=($!)
ready=
for _ in $(seq 1 100); do
    state=$(sinfo -h -N -o %t 2>/dev/null | head -1)
    if [ "$state" = "idle" ]; then ready=1; break; fi
    sleep 0.1
done
[ -n "$ready" ] || fail "the node did not come up (state '${state:-}'):
$(tail -5 "$tmp"/log/slurmctld.* 2>/dev/null)
$(tail -5 "$tmp"/log/slurmd.* 2>/dev/null)"
say "cluster up: $(sinfo -h -o '%P %D %C %t')"

# The showcase as a 72-frame turntable, 5 degrees a frame, small.
scene=$tmp/turntable.toml
sed -e "s#\.\./assets/#$repo/assets/#" \
    -e 's/^width = 640/width = 96/' -e 's/^height = 480/height = 72/' \
    -e 's/^frames = 48/frames = 72/' \
    -e '/^video = /d' -e '/^gif = /d' -e '/^gif_delay_ms/d' -e '/^gif_dither/d' \
    "$repo/scenes/showcase.toml" > "$scene"

start=$(date +%s.%N)
jobout=$(cd "$tmp" && SOFTRASTER=$bin sbatch --parsable --wait --array=0-3 \
    --cpus-per-task=1 --export=ALL,FRAMES=72,SOFTRASTER="$bin" \
    "$repo/scripts/slurm-array.sh" "$scene" --out "$tmp/shards" 2>&1)
status=$?
elapsed=$(echo "$(date +%s.%N) - $start" | bc)
say "sbatch --array=0-3 --wait: exit $status after ${elapsed} s (job $jobout)"
for f in "$tmp"/slurm-*_*.out; do
    [ -f "$f" ] || continue
    frames=$(grep -c '"event":"frame"' "$f")
    say "  $(basename "$f"): $frames frame events"
done
[ "$status" -eq 0 ] || fail "the job array failed:
$(cat "$tmp"/slurm-*.out 2>/dev/null | tail -20)"

"$bin" render "$scene" --out "$tmp/single" --quiet || fail "the one-process render failed"
shard_files=$(cd "$tmp/shards" && ls | sort)
single_files=$(cd "$tmp/single" && ls | sort)
[ "$shard_files" = "$single_files" ] || fail "the shards wrote other files than one run:
$(diff <(echo "$shard_files") <(echo "$single_files") | head)"
n=$(echo "$shard_files" | wc -l)
for f in $shard_files; do
    cmp -s "$tmp/shards/$f" "$tmp/single/$f" || fail "$f differs between the shards and one run"
done
say "OK: $n files from 4 shards are byte-identical to one process's render"
exit 0
