#!/usr/bin/env bash
# The billion-triangle issue's measurements. For builtin:room at each size and accelerator:
# a render (320x240, 1 spp, depth 3, 2 threads) whose stats JSON holds the OS's resident
# memory by phase, bytes per triangle and build seconds; a size that cannot fit is refused
# up front (scene-size check) and listed as such. Then the speed of 1M diffuse rays at 8M and
# 64M, and chunked against monolithic in one bench run. Prints one table at the end.
# Usage: bench/scale_suite.sh OUT_DIR [SIZES]   (SIZES default "8M 64M 256M"; 256M takes ~20 min)
set -uo pipefail
out=${1:-out/scale}
sizes=${2:-"8M 64M 256M"}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
for size in $sizes; do
  for accel in embree bvh raystrips hmq; do
    name="room_${size}_${accel}"
    /usr/bin/time -f "%M" -o "$out/$name.maxrss_kb" "$wavetrace" render "builtin:room:$size" --accel "$accel" \
        --size 320x240 --spp 1 --threads 2 --set render.max_depth=3 --stats "$out/$name.json" \
        --out "$out/$name.exr" > "$out/$name.txt" 2>&1 || echo "$name: $(tail -1 "$out/$name.txt")"
  done
done
for size in 8M 64M; do
  "$wavetrace" bench accel --scene "builtin:room:$size" --accel embree,bvh,raystrips,hmq --rays diffuse \
      --count 1000000 --threads 2 --repeat 3 --one-at-a-time --json "$out/bench_${size}.json" > "$out/bench_${size}.txt" 2>&1
done
# Chunked (1M) against monolithic (one chunk of 2^30) on the same mesh, against robust Embree.
whole=chunk_triangles=1073741824
chunked=chunk_triangles=1048576
for rays in primary diffuse; do
  "$wavetrace" bench accel --scene builtin:room:8M --rays "$rays" --count 1000000 --threads 2 --repeat 3 \
      --reference embree:mode=robust \
      --accel "hmq:$whole,hmq:$chunked,raystrips:$whole,raystrips:$chunked,bvh:$whole,bvh:$chunked" \
      --json "$out/chunked_8M_$rays.json" > "$out/chunked_8M_$rays.txt" 2>&1
done
/usr/bin/python3 "$(dirname "$0")/scale_table.py" "$out" $sizes
