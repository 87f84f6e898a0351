#!/usr/bin/env bash
# Submits a pipeline as a Slurm job array of n shards plus its merge job, which runs once every
# element has succeeded (afterok).
#
#   deploy/slurm/submit.sh [options] PIPELINE SHARDS [-- PIPELINE_ARGS...]
#
#   PIPELINE       label-seeds | eval | limit (deploy/slurm/PIPELINE.sbatch)
#   SHARDS         n: array elements 0..n-1, element i runs `--shard i/n`
#   --throttle K   at most K elements run at once (default: all)
#   --cpus C       CPUs (and worker threads) per element (default: the sbatch script's)
#   --logs DIR     where the jobs' output goes (default: target/slurm-logs)
#   --parsable     print only "ARRAY_JOB_ID MERGE_JOB_ID"
#
# The checkout must be on storage every node sees, and so must the pipelines' journal and output
# directories (the defaults lie in the checkout). Unless EMG_XTASK names an xtask binary already,
# target/release/xtask is built first, once, so that no element compiles.
#
# Resuming: run the same command again. Every pipeline skips the work already journaled (finished
# label chunks, eval shard files with the same inputs, limit task files), so a re-submitted array
# redoes only what a killed, failed or preempted element left. The merge job of an array with a
# failed element never runs (its dependency cannot be satisfied): `scancel` it, or let a cluster
# with `SchedulerParameters=kill_invalid_depend` cancel it.
set -euo pipefail

usage() {
    sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
    exit 2
}

throttle=""
cpus=""
parsable=0
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
logs="$root/target/slurm-logs"
while [[ $# -gt 0 ]]; do
    case "$1" in
        --throttle) throttle="${2:?--throttle needs a number}"; shift 2 ;;
        --cpus) cpus="${2:?--cpus needs a number}"; shift 2 ;;
        --logs) logs="${2:?--logs needs a directory}"; shift 2 ;;
        --parsable) parsable=1; shift ;;
        -h|--help) usage ;;
        -*) echo "submit.sh: unknown option $1" >&2; usage ;;
        *) break ;;
    esac
done
[[ $# -ge 2 ]] || usage
pipeline="$1"
shards="$2"
shift 2
if [[ $# -gt 0 ]]; then
    [[ "$1" == "--" ]] || { echo "submit.sh: pipeline arguments go after --" >&2; usage; }
    shift
fi
script="$root/deploy/slurm/$pipeline.sbatch"
[[ -f "$script" ]] || { echo "submit.sh: no pipeline '$pipeline' (deploy/slurm/$pipeline.sbatch)" >&2; exit 2; }
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: SHARDS must be a positive integer, not '$shards'" >&2; exit 2; }
[[ -z "$throttle" || "$throttle" =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: --throttle must be a positive integer, not '$throttle'" >&2; exit 2; }
[[ -z "$cpus" || "$cpus" =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: --cpus must be a positive integer, not '$cpus'" >&2; exit 2; }

if [[ -z "${EMG_XTASK:-}" ]]; then
    (cd "$root" && cargo build --release --quiet -p xtask)
    EMG_XTASK="$root/target/release/xtask"
fi
[[ -x "$EMG_XTASK" ]] || { echo "submit.sh: EMG_XTASK ($EMG_XTASK) is not an executable" >&2; exit 2; }
mkdir -p "$logs"

export EMG_ROOT="$root" EMG_XTASK EMG_SHARDS="$shards"
common=(--parsable --export=ALL "--chdir=$root")
[[ -n "$cpus" ]] && common+=("--cpus-per-task=$cpus")
array="0-$((shards - 1))${throttle:+%$throttle}"
array_id="$(sbatch "${common[@]}" "--array=$array" "--output=$logs/%x-%A_%a.out" \
    "$script" "$@")"
array_id="${array_id%%;*}"
merge_id="$(sbatch "${common[@]}" "--dependency=afterok:$array_id" "--output=$logs/%x-merge-%j.out" \
    "$script" "$@")"
merge_id="${merge_id%%;*}"
if [[ "$parsable" -eq 1 ]]; then
    echo "$array_id $merge_id"
else
    echo "submitted $pipeline: array job $array_id ($shards shards${throttle:+, at most $throttle at once}), merge job $merge_id after it"
    echo "logs: $logs; watch with: squeue -j $array_id,$merge_id"
fi
