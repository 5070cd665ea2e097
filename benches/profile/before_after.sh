#!/usr/bin/env bash
# Samples per second of two prism binaries on every shipped scene, runs
# interleaved (A, B, A, B) so machine load falls on both alike; the faster
# of each binary's runs is kept. Usage:
#   benches/profile/before_after.sh OLD_BINARY NEW_BINARY [THREADS] [SPP] > table.csv
# Each render is 256×192 at SPP samples (SPPM scenes: SPP/4 iterations), with
# a fixed seed; the time is the whole process's (scene load and BVH build
# included; both are small against the render at these sizes).
set -euo pipefail
old=$1 new=$2 threads=${3:-2} spp=${4:-64}
cd "$(dirname "$0")/../.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "scene,integrator,threads,samples,old_seconds,new_seconds,old_samples_per_s,new_samples_per_s,speedup"
for scene in scenes/*.toml; do
  name=$(basename "$scene" .toml)
  integrator=pt; count=$spp
  if grep -q '^integrator *= *"sppm"' "$scene"; then integrator=sppm; count=$((spp / 4)); fi
  best_old=1e9 best_new=1e9
  for round in 1 2; do
    for which in old new; do
      binary=$old; [ $which = new ] && binary=$new
      start=$(date +%s.%N)
      "$binary" render "$scene" --width 256 --height 192 --spp "$count" --threads "$threads" \
        --seed 7 --integrator "$integrator" --quiet -o "$out/$which.exr" >/dev/null 2>&1
      seconds=$(echo "$(date +%s.%N) - $start" | bc -l)
      if [ $which = old ]; then best_old=$(echo "if ($seconds < $best_old) $seconds else $best_old" | bc -l)
      else best_new=$(echo "if ($seconds < $best_new) $seconds else $best_new" | bc -l); fi
    done
  done
  samples=$((256 * 192 * count))
  printf "%s,%s,%s,%s,%.3f,%.3f,%.0f,%.0f,%.2f\n" "$name" "$integrator" "$threads" "$samples" "$best_old" "$best_new" \
    "$(echo "$samples / $best_old" | bc -l)" "$(echo "$samples / $best_new" | bc -l)" "$(echo "$best_old / $best_new" | bc -l)"
done
