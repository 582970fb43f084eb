#!/usr/bin/env bash
# Slurm job array: task i runs shard i of N of a cstab matrix, N = array size.
#
#   jid=$(sbatch --parsable --array=1-8 scripts/slurm-matrix.sh [MATRIX_FILE])
#   sbatch --dependency=afterok:$jid --wrap "build/release/cli/cstab merge results/merged results/shard-*"
#
# Without MATRIX_FILE the embedded default matrix runs. Environment: CSTAB
# (binary, default build/release/cli/cstab), OUT (parent of the shard
# folders, default results). See docs/cluster.md.
#SBATCH --job-name=cstab-matrix
#SBATCH --cpus-per-task=4
#SBATCH --time=01:00:00
#SBATCH --output=slurm-cstab-%A_%a.out
set -euo pipefail
cstab=${CSTAB:-build/release/cli/cstab}
out=${OUT:-results}
: "${SLURM_ARRAY_TASK_ID:?not an array task: submit with sbatch --array=1-N}"
min=${SLURM_ARRAY_TASK_MIN:-1}
max=${SLURM_ARRAY_TASK_MAX:-$SLURM_ARRAY_TASK_ID}
n=${SLURM_ARRAY_TASK_COUNT:-$((max - min + 1))}
k=$((SLURM_ARRAY_TASK_ID - min + 1))
jobs=${SLURM_CPUS_PER_TASK:-1}
echo "cstab shard $k/$n on $(hostname), $jobs cores"
exec "$cstab" matrix "$@" --shard "$k/$n" --out "$out/shard-$k" --jobs "$jobs"
