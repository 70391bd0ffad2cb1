#!/usr/bin/env bash
# The HMQ issue's measurements (the paper's Table 2): embree, bvh and hmq at leaf sizes 4, 8
# and 12 on the 1M and 8M spheres, a scanned mesh subdivided past 1M triangles and the
# terrain, primary and diffuse rays, 1 and 2 threads; leaks at q = 8, 12, 16; and the
# speed-against-accuracy table for q = 8 .. 20 (bytes, Mrays/s, t error, image RMSE).
# Usage: bench/hmq_suite.sh OUT_DIR   (about 20 minutes on 2 cores)
set -euo pipefail
out=${1:-out/hmq}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
accels=embree,bvh,hmq:leaf_size=4,hmq,hmq:leaf_size=12
for threads in 1 2; do
  for scene in builtin:sphere:1M builtin:sphere:8M data/bunny00.off builtin:terrain:1M; do
    name=$(basename "$scene" | tr ':' '_')
    extra=()
    [[ $scene == data/bunny00.off ]] && extra=(--set scene.subdivide=2)  # 75k -> 1.2M triangles
    for rays in primary diffuse; do
      "$wavetrace" bench accel --scene "$scene" "${extra[@]}" --accel "$accels" --rays "$rays" --count 1000000 \
          --threads "$threads" --repeat 3 --json "$out/${name}_${rays}_t$threads.json" | tee "$out/${name}_${rays}_t$threads.txt"
    done
  done
done
for scene in builtin:sphere:1M builtin:room:1M; do
  "$wavetrace" bench leak --scene "$scene" --accel embree:mode=robust,hmq:bits=8,hmq:bits=12,hmq:bits=16 \
      --count 2000000 | tee "$out/leak_$(echo "$scene" | tr ':' '_').txt"
done
quantized=embree:mode=robust,bvh,hmq:bits=8,hmq:bits=10,hmq:bits=12,hmq:bits=14,hmq:bits=16,hmq:bits=20
"$wavetrace" bench accel --scene builtin:sphere:1M --accel "$quantized" --reference embree:mode=robust --rays primary \
    --count 1000000 --threads 1 --repeat 3 --json "$out/bits_sphere1M.json" | tee "$out/bits_sphere1M.txt"
"$wavetrace" bench accel --scene data/bunny00.off --set scene.subdivide=2 --accel "$quantized" --reference embree:mode=robust \
    --rays primary --count 1000000 --threads 1 --repeat 3 --json "$out/bits_bunny.json" | tee "$out/bits_bunny.txt"
for scene in builtin:room:1M data/bunny00.off; do
  extra=()
  [[ $scene == data/bunny00.off ]] && extra=(--set scene.subdivide=2)
  "$wavetrace" bench image --scene "$scene" "${extra[@]}" --accel "$quantized" --size 640x480 --spp 16 \
      --json "$out/image_$(basename "$scene" | tr ':' '_').json" | tee "$out/image_$(basename "$scene" | tr ':' '_').txt"
done
