#!/usr/bin/env bash
# The Ray-Strips issue's measurements (the paper's Tables 1-4): embree, bvh and raystrips on
# the 1M and 8M spheres, a scanned mesh subdivided past 1M triangles and the soup, primary
# (single rays and 2x2 packets) and diffuse rays, 1 and 2 threads; leaks on closed meshes;
# the stripifier, sub-mesh and strips-per-leaf trade-offs.
# Usage: bench/raystrips_suite.sh OUT_DIR   (about 25 minutes on 2 cores)
set -euo pipefail
out=${1:-out/raystrips}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
accels=embree,bvh,raystrips
for threads in 1 2; do
  for scene in builtin:sphere:1M builtin:sphere:8M data/bunny00.off builtin:soup:1M; do
    name=$(basename "$scene" | tr ':' '_')
    extra=()
    [[ $scene == data/bunny00.off ]] && extra=(--set scene.subdivide=2)  # 75k -> 1.2M triangles
    for rays in primary diffuse; do
      "$wavetrace" bench accel --scene "$scene" "${extra[@]}" --accel "$accels" --rays "$rays" --count 1000000 \
          --threads "$threads" --repeat 3 --json "$out/${name}_${rays}_t$threads.json" | tee "$out/${name}_${rays}_t$threads.txt"
    done
    "$wavetrace" bench accel --scene "$scene" "${extra[@]}" --accel "$accels" --rays primary --packets --count 1000000 \
        --threads "$threads" --repeat 3 --json "$out/${name}_packets_t$threads.json" | tee "$out/${name}_packets_t$threads.txt"
  done
done
for scene in builtin:sphere:1M builtin:room:1M; do
  "$wavetrace" bench leak --scene "$scene" --accel embree:mode=robust,bvh,raystrips,raystrips:stripifier=dual_path \
      --count 2000000 | tee "$out/leak_$(echo "$scene" | tr ':' '_').txt"
done
"$wavetrace" bench accel --scene builtin:sphere:1M --rays diffuse --count 1000000 --threads 1 --repeat 3 \
    --accel bvh,raystrips,raystrips:stripifier=dual_path,raystrips:run_triangles=2,raystrips:submesh_triangles=64,raystrips:submesh_triangles=1024,raystrips:strips_per_leaf=4 \
    --json "$out/tradeoffs_sphere1M.json" | tee "$out/tradeoffs_sphere1M.txt"
