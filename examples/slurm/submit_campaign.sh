#!/bin/bash
# Runs a campaign over a Slurm cluster: an array of N shards, then their merge once every shard is done
# (docs/campaign.md, "Shards and Slurm").
#   examples/slurm/submit_campaign.sh SPEC OUT N [sbatch options...]
# e.g. examples/slurm/submit_campaign.sh examples/campaign.yaml /shared/campaign 16 --partition=batch
# Prints the array's and the merge's job ids; the result is OUT/merged/report.md. The sbatch options go
# to both jobs (they override the scripts' #SBATCH lines, e.g. --cpus-per-task=8).
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 SPEC OUT N [sbatch options...]" >&2
  exit 2
fi
spec=$1 out=$2 n=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
array=$(sbatch --parsable --array="1-$n" --output="$out/slurm-%A_%a.out" "$@" \
  "$here/campaign_array.sbatch" "$spec" "$out")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterok:$array" --output="$out/slurm-%j.out" "$@" \
  "$here/campaign_merge.sbatch" "$out" "$n")
merge=${merge%%;*}
echo "array job $array ($n shards), merge job $merge -> $out/merged/report.md"
