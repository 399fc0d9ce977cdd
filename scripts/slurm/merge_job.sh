#!/usr/bin/env bash
# Joins the shards of a recruit sweep (scripts/slurm/sweep_array.sh) into OUT_DIR/merged: the
# same table.csv, table.md and report an unsharded sweep writes. Give the same sweep arguments.
#
#   sbatch --dependency=afterany:JOBID --export=ALL,RECRUIT=$PWD/build/src/cli/recruit \
#     scripts/slurm/merge_job.sh OUT_DIR --sweep models/sweeps/bench_dT_N_noise.json
#
# If a shard failed, merge exits 3 naming the shards to resubmit (sbatch --array=LIST
# sweep_array.sh ...); they resume, then run this again.
#SBATCH --job-name=recruit-merge
#SBATCH --cpus-per-task=1
#SBATCH --output=recruit-merge_%j.log
set -euo pipefail
RECRUIT=${RECRUIT:-recruit}
out=$1
shift
exec "$RECRUIT" sweep merge "$@" --out "$out/merged" "$out"/shard_*
