#!/usr/bin/env bash
# The grids issue's measurements: every grid next to bvh and Embree on primary rays at 1 and
# 2 threads (the paper's Table 1), leaks on closed meshes, and the failure case builtin:stadium.
# Usage: bench/grid_suite.sh OUT_DIR   (about 10 minutes on 2 cores)
set -euo pipefail
out=${1:-out/grids}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
accels=embree,bvh,arraygrid,grid,mlgrid
for threads in 1 2; do
  for scene in builtin:sphere:1M builtin:sphere:8M data/bunny00.off builtin:terrain:1M; do
    name=$(basename "$scene" | tr ':' '_')
    extra=()
    [[ $scene == data/bunny00.off ]] && extra=(--set scene.subdivide=2)  # 75k -> 1.2M triangles
    "$wavetrace" bench accel --scene "$scene" "${extra[@]}" --accel "$accels" --rays primary --count 500000 \
        --threads "$threads" --repeat 3 --json "$out/${name}_t$threads.json" | tee "$out/${name}_t$threads.txt"
  done
  # The failure case: a dense sphere in a huge box puts the sphere in a handful of cells.
  "$wavetrace" bench accel --scene builtin:stadium:1M --accel "$accels" --rays primary --count 20000 \
      --threads "$threads" --repeat 1 --json "$out/stadium_t$threads.json" | tee "$out/stadium_t$threads.txt"
done
"$wavetrace" bench leak --scene builtin:sphere:1M --accel embree,embree:mode=robust,arraygrid,grid,mlgrid \
    --count 2000000 | tee "$out/leak_sphere1M.txt"
