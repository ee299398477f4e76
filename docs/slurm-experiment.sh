#!/usr/bin/env bash
# An experiment split over a cluster: one Slurm array task per shard, each
# writing its own directory; merge them when all have finished:
#
#   sbatch --array=1-16 docs/slurm-experiment.sh experiments/strategies.toml out/strategies
#   cpsplan experiment merge out/strategies-shard-* --out out/strategies
#
# A task that was cut short (time limit, preemption) is resubmitted as is:
# --resume keeps its whole records and runs the rest.
#SBATCH --job-name=cpsplan
#SBATCH --cpus-per-task=4
#SBATCH --mem=8G
#SBATCH --time=04:00:00
#SBATCH --requeue
#SBATCH --output=cpsplan-%A-%a.log
set -euo pipefail
file=${1:?usage: sbatch --array=1-N docs/slurm-experiment.sh FILE.toml OUTPREFIX}
prefix=${2:?usage: sbatch --array=1-N docs/slurm-experiment.sh FILE.toml OUTPREFIX}
k=${SLURM_ARRAY_TASK_ID:?run as an array job: sbatch --array=1-N}
n=${SLURM_ARRAY_TASK_COUNT:?run as an array job: sbatch --array=1-N}
out="$prefix-shard-$k"
resume=()
if [ -e "$out/plan.json" ]; then
    resume=(--resume)
fi
exec "${CPSPLAN:-cpsplan}" experiment "$file" --out "$out" --shard "$k/$n" \
    --jobs "${SLURM_CPUS_PER_TASK:-1}" --quiet "${resume[@]}"
