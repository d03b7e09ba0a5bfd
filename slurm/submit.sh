#!/usr/bin/env bash
# Submits a monitor-mc campaign to Slurm: a job array of SHARDS shard jobs, then a merge job
# that starts when all of them have succeeded (afterok). Prints the two job ids.
#   slurm/submit.sh RUNS FAULT_RUNS SHARDS [SEED] [DIR]
# DIR (default ./mc-campaign) gets part-K.json, report.json and the logs; the merge also writes
# docs/monitor.md unless MC_MERGE_ARGS holds --no-doc. NOBACK_XTASK: the xtask binary to run
# (default: this checkout's, built once here so the jobs do not all run cargo).
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: slurm/submit.sh RUNS FAULT_RUNS SHARDS [SEED] [DIR]" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
export MC_RUNS=$1 MC_FAULT_RUNS=$2 MC_SEED=${4:-2026}
shards=$3
MC_DIR=$(mkdir -p "${5:-mc-campaign}" && cd "${5:-mc-campaign}" && pwd)
export MC_DIR
if [ -z "${NOBACK_XTASK:-}" ]; then
  (cd "$root" && cargo build --quiet -p xtask)
  export NOBACK_XTASK="$root/target/debug/xtask"
fi
array=$(sbatch --parsable --array=0-$((shards - 1)) --chdir="$root" \
  --output="$MC_DIR/shard-%a.log" --export=ALL "$here/monitor-mc-shard.sbatch")
array=${array%%;*}
merge=$(sbatch --parsable --dependency=afterok:"$array" --kill-on-invalid-dep=yes \
  --chdir="$root" --output="$MC_DIR/merge.log" --export=ALL "$here/monitor-mc-merge.sbatch")
echo "$array ${merge%%;*}"
