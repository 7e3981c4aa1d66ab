#!/usr/bin/env bash
# A parameter scan as a SLURM job array: task K of N runs `stepbench scan --shard K/N`
# (a deterministic share of the grid points), then a dependent job merges the shards.
# Submit from the repository root, after scripts/build.sh on the cluster:
#   jid=$(sbatch --parsable --array=1-8 scripts/slurm/scan-array.sh \
#         --problem stiff_spring --param stiff_spring.k_s=1e1:1e7:25:log --hz 30,60,120,240)
#   sbatch --dependency=afterok:$jid --wrap \
#         "build/stepbench merge results/shards/shard-*.h5 -o results/scan.h5"
# Every task must run the same build (merge refuses shards of another build).
#SBATCH --job-name=stepbench-scan
#SBATCH --cpus-per-task=2
#SBATCH --time=01:00:00
#SBATCH --output=results/shards/slurm-%A_%a.out
set -euo pipefail
: "${SLURM_ARRAY_TASK_ID:?run this with sbatch --array=1-N}"
: "${SLURM_ARRAY_TASK_COUNT:?run this with sbatch --array=1-N}"
mkdir -p results/shards
exec build/stepbench scan "$@" --jobs "${SLURM_CPUS_PER_TASK:-0}" \
  --shard "${SLURM_ARRAY_TASK_ID}/${SLURM_ARRAY_TASK_COUNT}" --quiet \
  --out "results/shards/shard-${SLURM_ARRAY_TASK_ID}.h5"
