#!/usr/bin/env bash
# Submits a Prism render as a Slurm job array of N parts plus a merge job
# that runs when all of them have succeeded (--dependency=afterok). Prints
# the two job ids ("ARRAY_ID MERGE_ID").
#
#   deploy/slurm/submit.sh SCENE PARTS OUTPUT PARTS_DIR [prism render flags...]
#
# e.g. deploy/slurm/submit.sh /shared/scenes/cornell.toml 16 /shared/out/cornell.exr \
#        /shared/out/parts --spp 4096 --seed 7
# SCENE, PARTS_DIR and OUTPUT must be on storage every node shares. Set
# PRISM to the prism binary if it is not on PATH, and SBATCH_* variables
# or extra sbatch options in SBATCH_OPTIONS (e.g. "--partition=render").
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n '2,13p' "$0" >&2
  exit 2
fi
scene=$1 parts=$2 output=$3 parts_dir=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
export PRISM_SCENE=$scene PRISM_PARTS=$parts_dir PRISM_OUTPUT=$output PRISM_ARGS="$*"
export PRISM=${PRISM:-prism}
mkdir -p "$parts_dir"
# shellcheck disable=SC2086
array=$(sbatch --parsable ${SBATCH_OPTIONS:-} --array="0-$((parts - 1))" "$here/render.sbatch")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTIONS:-} --dependency="afterok:$array" --kill-on-invalid-dep=yes "$here/merge.sbatch")
merge=${merge%%;*}
echo "$array $merge"
