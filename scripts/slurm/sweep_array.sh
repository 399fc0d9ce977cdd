#!/usr/bin/env bash
# One shard of a recruit sweep as a Slurm job-array task (docs/sweep.md, "On a Slurm cluster").
#
#   sbatch --array=1-8 --export=ALL,SHARDS=8,RECRUIT=$PWD/build/src/cli/recruit \
#     scripts/slurm/sweep_array.sh OUT_DIR --sweep models/sweeps/bench_dT_N_noise.json
#
# Task K runs `recruit sweep ARGS --shard K/SHARDS --out OUT_DIR/shard_K` on the task's CPUs. A
# shard is resumable: resubmitting a failed task (sbatch --array=3,7 ...) keeps the runs it had
# finished. SHARDS is the whole array's size (not SLURM_ARRAY_TASK_COUNT, which is the size of a
# resubmission). Join the shards with scripts/slurm/merge_job.sh (submit.sh does both).
#SBATCH --job-name=recruit-sweep
#SBATCH --cpus-per-task=2
#SBATCH --output=recruit-sweep_%A_%a.log
set -euo pipefail
: "${SHARDS:?set SHARDS=N (the full size of the array), e.g. sbatch --export=ALL,SHARDS=8}"
: "${SLURM_ARRAY_TASK_ID:?submit with sbatch --array=1-$SHARDS}"
RECRUIT=${RECRUIT:-recruit}
out=$1
shift
k=$SLURM_ARRAY_TASK_ID
echo "recruit sweep shard $k/$SHARDS on $(hostname) (job ${SLURM_ARRAY_JOB_ID:-?}_$k)"
exec "$RECRUIT" sweep "$@" --shard "$k/$SHARDS" --out "$out/shard_$k" \
  --threads "${SLURM_CPUS_PER_TASK:-0}" --progress
