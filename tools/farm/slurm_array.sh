#!/usr/bin/env bash
# An example Slurm array job: 10 tasks render one animation into a shared directory.
#   sbatch tools/farm/slurm_array.sh shot.json /shared/out
# Each task renders every 10th frame (`--shard auto` reads SLURM_ARRAY_TASK_ID, minus
# SLURM_ARRAY_TASK_MIN, and SLURM_ARRAY_TASK_COUNT). Requeued or re-submitted tasks resume:
# --skip-existing leaves finished frames alone, --placeholders keeps two tasks from ever
# rendering the same frame. Exit status 4 (I/O) is worth a retry, 3 (scene) is not; see
# `octray render --help`.
#SBATCH --job-name=octray
#SBATCH --array=0-9
#SBATCH --cpus-per-task=8
#SBATCH --time=02:00:00
#SBATCH --requeue
#SBATCH --output=octray-%A_%a.log
set -euo pipefail
scene=${1:?usage: sbatch slurm_array.sh SCENE OUTDIR}
out=${2:?usage: sbatch slurm_array.sh SCENE OUTDIR}
mkdir -p "$out"
# Slurm sends SIGTERM before it kills a task at its time limit: octray then abandons the
# frame in progress without leaving a partial file, and the requeued task resumes.
exec octray render "$scene" \
  --shard auto --skip-existing --placeholders \
  --threads "${SLURM_CPUS_PER_TASK:-0}" \
  --progress lines \
  -o "$out/{scene}.####.exr"
