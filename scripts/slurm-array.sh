#!/bin/bash
#SBATCH --job-name=softraster
#SBATCH --requeue
#SBATCH --output=slurm-%A_%a.out
# One shard of a softraster render as a Slurm job-array task: the scene's
# FRAMES frames split into SLURM_ARRAY_TASK_COUNT runs of consecutive
# frames, this task rendering number SLURM_ARRAY_TASK_ID. Every frame's
# files depend on the scene and the frame number only, so the shards'
# union is byte-identical to one run.
#
#   sbatch --array=0-7 --cpus-per-task=4 --export=ALL,FRAMES=72 \
#       scripts/slurm-array.sh scenes/melina.toml --out out/melina
#
# SOFTRASTER: the binary (default: softraster on PATH). Extra arguments go
# to `softraster render` after the scene.
set -u
scene=$1
shift
count=${SLURM_ARRAY_TASK_COUNT:?run as a job array (sbatch --array=...)}
id=${SLURM_ARRAY_TASK_ID:?run as a job array (sbatch --array=...)}
per=$(( (FRAMES + count - 1) / count ))
first=$(( id * per ))
last=$(( first + per > FRAMES ? FRAMES : first + per ))
if [ "$first" -ge "$last" ]; then
    echo "task $id of $count: no frames left"
    exit 0
fi
"${SOFTRASTER:-softraster}" render "$scene" --frames "${first}..${last}" \
    --threads "${SLURM_CPUS_PER_TASK:-1}" --skip-existing --progress json "$@"
status=$?
# 2: the scene or an asset is wrong; retrying cannot help, stop the array.
if [ "$status" -eq 2 ]; then
    scancel "$SLURM_ARRAY_JOB_ID"
fi
exit "$status"
