#!/bin/bash
# Build a Slipgate project as a Slurm array job: one task per shard, then one job that checks
# the shards make the whole project.
#
#   sbatch docs/batch/slurm.sh                 # the array of shards
#   sbatch --dependency=afterany:JOBID --wrap "slipgate batch --collect build/shard-*"
#
# Each task writes to build/shard-K/ with a cache of its own on node-local disk (the cache is
# keyed by content, so a shared one on a network file system works too; files are written
# atomically).
#SBATCH --job-name=slipgate-maps
#SBATCH --array=1-8
#SBATCH --cpus-per-task=8
#SBATCH --mem=16G
#SBATCH --time=04:00:00
#SBATCH --output=build/logs/shard-%a.log

set -euo pipefail
SHARDS=${SLURM_ARRAY_TASK_COUNT:-8}
K=${SLURM_ARRAY_TASK_ID:?run as an array job}

slipgate batch project.toml \
    --shard "$K/$SHARDS" \
    --jobs "$SLURM_CPUS_PER_TASK" \
    --memory-budget 14G \
    --output "build/shard-$K" \
    --cache "${TMPDIR:-/tmp}/slipgate-cache-$K"
