#!/usr/bin/env bash
# Issue 18's table: the megakernel against the wavefront (reorder none, origin, hph) at 1 and
# 2 threads on builtin:room:1M and room:8M, with Embree and the bvh baseline, and the Embree
# entry points (rtcIntersect1 against rtcIntersectNp) on room:1M.
# Usage: bench/pipeline_suite.sh OUT_DIR   (about 8 minutes on 2 cores)
set -euo pipefail
out=${1:-out/pipeline}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}

for accel in embree bvh; do
  for size in 1M 8M; do
    "$wavetrace" bench pipeline --scene "builtin:room:$size" --accel "$accel" --heuristics none,origin,hph \
        --threads 1,2 --repeat 3 --json "$out/room${size}_$accel.json" | tee "$out/room${size}_$accel.txt"
  done
done
for queries in single stream; do
  "$wavetrace" bench pipeline --scene builtin:room:1M --accel "embree:queries=$queries" --heuristics none \
      --threads 2 --repeat 5 --json "$out/room1M_embree_$queries.json" | tee "$out/room1M_embree_$queries.txt"
done
