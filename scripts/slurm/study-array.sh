#!/usr/bin/env bash
# The timed study as a SLURM job array: task K of N runs `stepbench_bench --shard=K/N`
# (a deterministic share of the problems, with every part of the study that belongs to
# them), then a dependent job merges the shards and their Google Benchmark JSON. Submit
# from the repository root, after scripts/build.sh on the cluster:
#   jid=$(sbatch --parsable --array=1-4 scripts/slurm/study-array.sh [--quick])
#   sbatch --dependency=afterok:$jid --wrap \
#         "build/stepbench merge results/shards/study-*/study.h5 -o results/study.h5 \
#          --bench results/shards/study-*/bench.json --bench-out results/bench.json"
# Every task must run the same build and options (merge refuses shards that differ).
# Each shard writes into its own folder: Google Benchmark's bench.json goes beside its
# study, and the two globs list the shards in the same order (merge checks each bench.json
# against its study: it names its shard).
# Nodes with different CPUs are allowed: each problem records the machine it was timed
# on, and timings are compared only within a problem.
#SBATCH --job-name=stepbench-study
#SBATCH --cpus-per-task=2
#SBATCH --time=01:00:00
#SBATCH --output=results/shards/slurm-%A_%a.out
set -euo pipefail
: "${SLURM_ARRAY_TASK_ID:?run this with sbatch --array=1-N}"
: "${SLURM_ARRAY_TASK_COUNT:?run this with sbatch --array=1-N}"
out="results/shards/study-${SLURM_ARRAY_TASK_ID}"
mkdir -p "$out"
exec build/stepbench_bench "$@" --shard="${SLURM_ARRAY_TASK_ID}/${SLURM_ARRAY_TASK_COUNT}" --study_out="$out/study.h5"
