#!/usr/bin/env bash
# Submits a recruit sweep to Slurm: a job array of SHARDS shards and a merge job that runs when
# the array is over (afterany: it reports failed shards instead of waiting forever).
#
#   scripts/slurm/submit.sh SHARDS OUT_DIR RECRUIT_SWEEP_ARGS...
#   scripts/slurm/submit.sh 16 /scratch/me/sweep1 --sweep models/sweeps/bench_dT_N_noise.json
#
# RECRUIT (default: build/src/cli/recruit of this checkout) must be reachable from the nodes;
# OUT_DIR must be on a file system the nodes share. Extra sbatch options: SBATCH_* variables
# (e.g. SBATCH_PARTITION=short, SBATCH_TIMELIMIT=60).
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n '2,10p' "$0"
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
shards=$1
out=$2
shift 2
RECRUIT=${RECRUIT:-$(cd "$here/../.." && pwd)/build/src/cli/recruit}
mkdir -p "$out"
array=$(sbatch --parsable --array="1-$shards" --chdir="$PWD" --output="$out/shard_%a.log" \
  --export="ALL,SHARDS=$shards,RECRUIT=$RECRUIT" "$here/sweep_array.sh" "$out" "$@")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterany:$array" --chdir="$PWD" \
  --output="$out/merge.log" --export="ALL,RECRUIT=$RECRUIT" "$here/merge_job.sh" "$out" "$@")
echo "array job $array ($shards shards), merge job ${merge%%;*}; logs in $out"
echo "follow: tail -f $out/shard_*/progress.log; resubmit failed shards: sbatch --array=LIST" \
  "--output=$out/shard_%a.log --export=ALL,SHARDS=$shards,RECRUIT=$RECRUIT" \
  "$here/sweep_array.sh $out $*"
