#!/usr/bin/env bash
# End-to-end test of the Slurm job arrays on a one-node cluster on the loopback address.
#
# Installs Debian's Slurm and MUNGE packages when missing, starts munged, slurmctld and slurmd
# with a generated configuration in a temporary state directory, and then, through submit.sh:
#   1. label-seeds as a 4-shard array (at most 2 at once) plus its merge; shard 0 is cancelled
#      mid-run, the whole array is re-submitted, shard 0 resumes from its journal chunks and the
#      others skip their finished chunks; the merged label file and manifest must equal, byte for
#      byte, those of a single run without Slurm;
#   2. eval (the seed x controller protocol, on those labels) as a 4-shard array plus its merge:
#      the merged eval.json must equal a single run's except the measured seed times, the only
#      wall-clock values it holds; a re-submitted array skips every finished shard;
#   3. limit on a few tasks as a 4-shard array plus its merge: limit.{json,md} byte-identical.
# Then stops the daemons, checks that none of its processes is left, and removes its state.
#
# Authentication: auth/munge with a key generated for this run and munged listening on a socket
# in the state directory (AuthInfo=socket=...): the credential path production clusters use,
# isolated from any system munged. Slurm 22.05 has no daemon authentication without MUNGE other
# than auth/none, which would not exercise credentials at all.
#
# EMG_SLURM_TEST_KEEP=1 keeps the state directory (logs, outputs) for a look afterwards.
# Needs root (or sudo) to install packages and run slurmd. Fails, never skips, when Slurm cannot
# start. Usage: deploy/slurm/test.sh (from anywhere) after `cargo test --workspace`, which builds
# target/debug/xtask; EMG_XTASK names another xtask binary.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
started_at=$SECONDS

fail() {
    echo "slurm test FAILED: $*" >&2
    exit 1
}
step() { echo "[slurm test +$((SECONDS - started_at))s] $*"; }
# Runs "${@:3}" every 50 ms until it succeeds; after $1 seconds fails saying it did not: $2.
wait_until() {
    local deadline=$((SECONDS + $1)) what=$2
    shift 2
    until "$@"; do
        [[ $SECONDS -lt $deadline ]] || fail "$what"
        sleep 0.05
    done
}

# --- Root, packages -----------------------------------------------------------------------------
as_root=()
if [[ "$(id -u)" -ne 0 ]]; then
    command -v sudo >/dev/null || fail "needs root or sudo (to install Slurm and run slurmd)"
    as_root=(sudo -E)
fi
packages=(slurmctld slurmd slurm-client munge)
missing=()
for package in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" \
        || missing+=("$package")
done
if [[ ${#missing[@]} -gt 0 ]]; then
    step "installing ${missing[*]}"
    "${as_root[@]}" apt-get update -qq
    "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        "${missing[@]}" >/dev/null
fi
for tool in munged slurmctld slurmd sbatch squeue scontrol scancel sinfo; do
    command -v "$tool" >/dev/null || fail "$tool is not on PATH after installing ${packages[*]}"
done

# --- xtask ------------------------------------------------------------------------------------
# The binary `cargo test --workspace` builds for xtask's integration tests (test profile, the
# workspace's feature set: building it alone would compile much of the dependency tree again).
export EMG_XTASK="${EMG_XTASK:-$root/target/debug/xtask}"
[[ -x "$EMG_XTASK" ]] \
    || fail "no xtask binary at $EMG_XTASK: run \`cargo test --workspace\` first (or set EMG_XTASK)"

# --- State and cleanup --------------------------------------------------------------------------
state="$(mktemp -d /tmp/emg-slurm-test.XXXXXX)"
chmod 755 "$state"
daemons=()
leftover_processes() {
    local pid
    for pid in $(pgrep -f -- "$state"; pgrep -x 'slurmstepd|slurmd|slurmctld|munged'); do
        [[ "$pid" -ne $$ ]] || continue
        "${as_root[@]}" grep -qsF -- "$state" "/proc/$pid/cmdline" "/proc/$pid/environ" && echo "$pid"
    done | sort -u
}
cleanup() {
    local status=$?
    set +e
    if [[ -f "$state/slurm.conf" ]]; then
        SLURM_CONF="$state/slurm.conf" scancel --quiet --user="$(id -un)" 2>/dev/null
        sleep 1
    fi
    for pid in "${daemons[@]}"; do
        "${as_root[@]}" kill -TERM "$pid" 2>/dev/null
    done
    for _ in $(seq 50); do
        local alive=0
        for pid in "${daemons[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
        [[ $alive -eq 0 ]] && break
        sleep 0.2
    done
    for pid in "${daemons[@]}"; do "${as_root[@]}" kill -KILL "$pid" 2>/dev/null; done
    wait 2>/dev/null
    # Everything the test started names its state directory in its command line or environment
    # (the daemons and the jobs' slurmstepd inherit SLURM_CONF); give exiting ones a moment.
    local left=""
    for _ in $(seq 50); do
        left="$(leftover_processes)"
        [[ -z "$left" ]] && break
        sleep 0.2
    done
    if [[ -n "$left" ]]; then
        echo "slurm test: processes left behind, killing them:" >&2
        ps -o pid,ppid,cmd -p "$(echo "$left" | paste -sd,)" >&2
        echo "$left" | xargs -r "${as_root[@]}" kill -KILL 2>/dev/null
        [[ $status -eq 0 ]] && status=1
    fi
    if [[ $status -ne 0 ]]; then
        for log in "$state"/log/*; do
            [[ -f "$log" ]] || continue
            echo "--- $log (last lines)" >&2
            tail -n 15 "$log" >&2
        done
    fi
    if [[ -n "${EMG_SLURM_TEST_KEEP:-}" ]]; then
        echo "slurm test: state kept in $state (EMG_SLURM_TEST_KEEP)" >&2
    else
        rm -rf "$state"
    fi
    exit $status
}
trap cleanup EXIT
trap 'echo "slurm test FAILED at line $LINENO: $BASH_COMMAND" >&2' ERR
trap 'exit 130' INT TERM
mkdir -p "$state"/{munge,run,spool,ctld,log,work}
chmod 700 "$state/munge"

# --- MUNGE --------------------------------------------------------------------------------------
step "starting munged and the cluster in $state"
dd if=/dev/urandom of="$state/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$state/munge/munge.key"
socket="$state/run/munge.socket"
munged --foreground --force --socket="$socket" --key-file="$state/munge/munge.key" \
    --pid-file="$state/run/munged.pid" --seed-file="$state/munge/seed" \
    --log-file="$state/log/munged.log" >>"$state/log/munged.log" 2>&1 &
daemons+=($!)
wait_until 10 "munged created no socket $socket within 10 s" test -S "$socket"
munge --socket="$socket" --no-input | unmunge --socket="$socket" >/dev/null \
    || fail "munged does not answer on $socket"

# --- Slurm --------------------------------------------------------------------------------------
port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
ctld_port=""
for port in $(seq 26817 2 26917); do
    if port_free "$port" && port_free $((port + 1)); then ctld_port=$port; break; fi
done
[[ -n "$ctld_port" ]] || fail "no free pair of ports in 26817..26918"
host="$(hostname -s)"
cpus="$(nproc)"
cat >"$state/slurm.conf" <<CONF
ClusterName=emg-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$((ctld_port + 1))
SlurmUser=$(id -un)
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/run/slurmctld.pid
SlurmdPidFile=$state/run/slurmd.pid
SlurmctldLogFile=$state/log/slurmctld.log
SlurmdLogFile=$state/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=emg Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$state/slurm.conf"
"${as_root[@]}" slurmctld -D -f "$SLURM_CONF" >>"$state/log/slurmctld.log" 2>&1 &
daemons+=($!)
"${as_root[@]}" slurmd -D -f "$SLURM_CONF" >>"$state/log/slurmd.log" 2>&1 &
daemons+=($!)
node_idle() { [[ "$(sinfo -h -n "$host" -o %t 2>/dev/null)" == "idle" ]]; }
wait_until 30 "the node did not come up idle within 30 s" node_idle
step "cluster up: node $host, $cpus CPUs, slurmctld on 127.0.0.1:$ctld_port"

# --- Helpers ------------------------------------------------------------------------------------
work="$state/work"
logs="$work/logs"
x() { "$EMG_XTASK" "$@" >>"$work/reference.log" 2>&1 || fail "xtask $1 failed (see $work/reference.log)"; }
# Submits an array of 4 shards (at most 2 at once, one CPU each) and its merge; sets $array and $merge.
submit() {
    local ids
    ids="$("$root/deploy/slurm/submit.sh" --parsable --logs "$logs" --throttle 2 --cpus 1 "$@")" \
        || fail "submit.sh $1 failed"
    read -r array merge <<<"$ids"
    [[ -n "$array" && -n "$merge" ]] || fail "submit.sh $1 printed no job ids: '$ids'"
}
# The states of every job (array elements one per line) of the given job ids.
job_states() {
    local id
    for id in "$@"; do
        scontrol show job "$id" | grep -o 'JobState=[A-Z_]*' | cut -d= -f2 \
            || fail "scontrol knows no job $id"
    done
}
# Waits (at most $1 s) until none of the jobs $2... is pending or running.
wait_jobs() {
    local limit=$1
    shift
    local ids
    ids="$(IFS=,; echo "$*")"
    jobs_over() { ! squeue -h -j "$ids" -t PENDING,RUNNING,CONFIGURING,COMPLETING 2>/dev/null | grep -q .; }
    wait_until "$limit" "jobs $ids still queued or running after ${limit} s" jobs_over
}
expect_completed() {
    local states
    states="$(job_states "$@" | sort -u | tr '\n' ' ')"
    [[ "$states" == "COMPLETED " ]] || fail "jobs $* ended as: $states(logs in $logs)"
}
same_bytes() { cmp -s "$1" "$2" || fail "$2 differs from the single run's $1"; }

# --- Task set and single runs (the references) -----------------------------------------------------
tasks="$work/tasks"
x make-tasks --eval-count 240 --train-count 0 --out-dir "$tasks"
label_args=(--set eval --tasks-dir "$tasks" --chunk-size 5)
# Both runs write to the same paths under $out (files record the paths they were made from); the
# single runs' outputs are then moved to $work/single.
out="$work/out"
step "single runs: label-seeds, eval, limit"
x label-seeds "${label_args[@]}" --threads 1 --journal-dir "$work/single-journal/labels" --out-dir "$out/labels"
eval_args=(--tasks "$tasks/eval-v1.tasks" --limit 48 --seen-count 0 --labels "$out/labels/eval-v1.labels"
    --out-dir "$out/eval")
x eval "${eval_args[@]}" --threads 1
limit_args=(--tasks 8 --task-file "$tasks/eval-v1.tasks" --out-dir "$out/limit")
x limit "${limit_args[@]}" --threads 1 --journal "$work/single-journal/limit"
x limit "${limit_args[@]}" --merge --journal "$work/single-journal/limit"
mv "$out" "$work/single"

# --- 1. label-seeds: kill shard 0 mid-run, re-submit, merge ------------------------------------------
journal="$work/slurm-journal/labels"
slurm_label_args=("${label_args[@]}" --journal-dir "$journal" --out-dir "$out/labels")
submit label-seeds 4 -- "${slurm_label_args[@]}"
step "label-seeds: array $array, merge $merge"
# Shard 0 owns chunks 0, 4, 8, ... (first tasks 0, 20, 40, ...): cancel it once its first chunk
# is written, while the rest of its 12 are still to do.
shard0_chunks() { find "$journal/eval-v1" -name 'chunk-*.labels' 2>/dev/null \
    | sed 's/.*chunk-0*\([0-9]*\)\.labels/\1/' | awk '$1 % 20 == 0' | wc -l; }
first_chunk() { [[ "$(shard0_chunks)" -ge 1 ]]; }
wait_until 120 "shard 0 wrote no chunk within 120 s" first_chunk
scancel "${array}_0"
wait_jobs 300 "$array"
killed_at="$(shard0_chunks)"
[[ "$(job_states "${array}_0")" == "CANCELLED" ]] || fail "shard 0 was not cancelled (state $(job_states "${array}_0"))"
[[ "$killed_at" -lt 12 ]] || fail "shard 0 finished all 12 chunks before it could be cancelled"
step "label-seeds: shard 0 cancelled after $killed_at of 12 chunks"
# The first merge job can never run now (afterok on a cancelled element): Slurm says so, and it
# is cancelled as submit.sh tells users to.
merge_blocked() { [[ "$(squeue -h -j "$merge" -o %r 2>/dev/null)" == "DependencyNeverSatisfied" ]]; }
wait_until 60 "the first merge job is not waiting on a failed dependency" merge_blocked
scancel "$merge"
[[ ! -e "$out/labels/eval-v1.labels" ]] || fail "a label file was written before every shard finished"
submit label-seeds 4 -- "${slurm_label_args[@]}"
wait_jobs 300 "$array" "$merge"
expect_completed "$array" "$merge"
grep -q ", $killed_at were already done" "$logs/emg-label-seeds-${array}_0.out" \
    || fail "the re-submitted shard 0 did not resume from its $killed_at journaled chunks"
for i in 1 2 3; do
    grep -q ": 0 chunks done.*, 12 were already done" "$logs/emg-label-seeds-${array}_$i.out" \
        || fail "the re-submitted shard $i did not skip its finished chunks"
done
same_bytes "$work/single/labels/eval-v1.labels" "$out/labels/eval-v1.labels"
same_bytes "$work/single/labels/eval-v1.manifest.json" "$out/labels/eval-v1.manifest.json"
step "label-seeds: resumed and merged, byte-identical to the single run"

# --- 2. eval --------------------------------------------------------------------------------------
submit eval 4 -- "${eval_args[@]}"
wait_jobs 300 "$array" "$merge"
expect_completed "$array" "$merge"
python3 - "$work/single/eval/eval.json" "$out/eval/eval.json" <<'PY' || fail "the merged eval.json differs from the single run's"
import json, sys
single, merged = (json.load(open(path)) for path in sys.argv[1:])
for record in (single, merged):
    for task_set in record["sets"]:
        del task_set["seed_time_ms"]  # measured wall-clock time: differs between any two runs
sys.exit(single != merged)
PY
submit eval 4 -- "${eval_args[@]}"
wait_jobs 120 "$array" "$merge"
expect_completed "$array" "$merge"
for i in 0 1 2 3; do
    grep -q "shard $i/4 is already done" "$logs/emg-eval-${array}_$i.out" \
        || fail "the re-submitted eval shard $i did not skip its finished shard file"
done
step "eval: merged tables equal the single run's; a re-submission skipped every shard"

# --- 3. limit -------------------------------------------------------------------------------------
submit limit 4 -- "${limit_args[@]}" --journal "$work/slurm-journal/limit"
wait_jobs 300 "$array" "$merge"
expect_completed "$array" "$merge"
same_bytes "$work/single/limit/limit.json" "$out/limit/limit.json"
same_bytes "$work/single/limit/limit.md" "$out/limit/limit.md"
step "limit: merged results byte-identical to the single run"
step "passed"
