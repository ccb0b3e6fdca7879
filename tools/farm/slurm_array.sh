#!/usr/bin/env bash
# An example Slurm array job: 10 tasks render one animation into a shared directory.
#   sbatch tools/farm/slurm_array.sh shot.json /shared/out [OCTRAY RENDER OPTIONS...]
# Each task renders every 10th frame (`--shard auto` reads SLURM_ARRAY_TASK_ID, minus
# SLURM_ARRAY_TASK_MIN, and SLURM_ARRAY_TASK_COUNT). Requeued or re-submitted tasks resume:
# --skip-existing leaves finished frames alone, --placeholders keeps two tasks from ever
# rendering the same frame. Exit status 4 (I/O) is worth a retry, 3 (scene) is not; see
# `octray render --help`. Options after OUTDIR go to `octray render` (e.g. --frames 1-100,
# --width 640). OCTRAY names the binary when it is not `octray` on PATH.
# Tested end to end on a single-node Slurm 22.05 by tests/farm/slurm.sh.
#SBATCH --job-name=octray
#SBATCH --array=0-9
#SBATCH --cpus-per-task=8
#SBATCH --time=02:00:00
#SBATCH --requeue
#SBATCH --output=octray-%A_%a.log
# A requeued task appends to its log instead of truncating the first attempt's lines.
#SBATCH --open-mode=append
set -euo pipefail
scene=${1:?usage: sbatch slurm_array.sh SCENE OUTDIR [OCTRAY RENDER OPTIONS...]}
out=${2:?usage: sbatch slurm_array.sh SCENE OUTDIR [OCTRAY RENDER OPTIONS...]}
shift 2
octray=${OCTRAY:-octray}
restarts=${SLURM_RESTART_COUNT:-0}
mkdir -p "$out"
echo "octray task ${SLURM_ARRAY_JOB_ID:-?}_${SLURM_ARRAY_TASK_ID:-?} on $(hostname)," \
  "attempt $((restarts + 1)) (SLURM_RESTART_COUNT=$restarts), $(date -u +%FT%TZ)"
# A task killed outright (SIGKILL, out of memory, a lost node) leaves the empty placeholder
# of the frame it was rendering, and an empty placeholder is a claim that every run skips.
# Slurm runs one attempt of an array task at a time, so on a retry (requeue) that claim is
# stale: release the empty placeholders before resuming. Another task's frame released
# here is never rendered by this task (--shard keeps the shards apart); at worst a
# re-submitted job renders it a second time, to the same pixels, written atomically.
if ((restarts > 0)); then
  find "$out" -maxdepth 1 -type f -empty -name '*.exr' -print -delete |
    sed 's/^/released stale placeholder: /'
fi
# Slurm sends SIGTERM before it kills a task at its time limit: octray then abandons the
# frame in progress without leaving a partial file, and the requeued task resumes.
exec "$octray" render "$scene" \
  --shard auto --skip-existing --placeholders \
  --threads "${SLURM_CPUS_PER_TASK:-0}" \
  --progress lines \
  -o "$out/{scene}.####.exr" "$@"
