# shellcheck shell=bash
# Sourced by the pipelines' sbatch scripts: checks the environment `submit.sh` exports and names
# this element's part of the job.
#
#   EMG_ROOT    the workspace checkout, on storage every node sees
#   EMG_XTASK   the xtask binary built from it (submit.sh builds target/release/xtask)
#   EMG_SHARDS  the number of shards n of the array (not SLURM_ARRAY_TASK_COUNT: a re-submission
#               of some elements only must keep the same n)
#
# An array element (SLURM_ARRAY_TASK_ID set) is shard `SLURM_ARRAY_TASK_ID/EMG_SHARDS`; a job
# without an array index is the merge.
set -euo pipefail
: "${EMG_ROOT:?EMG_ROOT must name the workspace checkout (submit.sh exports it)}"
: "${EMG_XTASK:?EMG_XTASK must name the xtask binary (submit.sh exports it)}"
: "${EMG_SHARDS:?EMG_SHARDS must give the number of shards (submit.sh exports it)}"
cd "$EMG_ROOT"
EMG_THREADS="${SLURM_CPUS_PER_TASK:-0}"
if [[ -n "${SLURM_ARRAY_TASK_ID:-}" ]]; then
    EMG_SHARD="${SLURM_ARRAY_TASK_ID}/${EMG_SHARDS}"
    echo "$(date -u +%FT%TZ) ${SLURM_JOB_NAME:-job} shard ${EMG_SHARD} on $(hostname) (${EMG_THREADS} threads)"
else
    EMG_SHARD=""
    echo "$(date -u +%FT%TZ) ${SLURM_JOB_NAME:-job} merge of ${EMG_SHARDS} shards on $(hostname)"
fi
