#!/usr/bin/env bash
# The reordering paper's tables on our scenes: Table III (every heuristic against none) at
# simulated memory budgets of 20% and 100% on builtin:room:8M and builtin:sphere:8M, and in
# core on builtin:room:1M; Table II (proxy share) and Table I (ray buffer) on room:8M at 20%.
# Usage: bench/reorder_suite.sh OUT_DIR   (about 10 minutes on 2 cores)
set -euo pipefail
out=${1:-out/reorder}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
paged=(--accel bvh --size 320x240 --spp 2 --threads 1 --set memory.page_bytes=4194304 --set memory.cache=paper_l2
       --set proxy.accel=bvh)

for scene in room sphere; do
  for budget in 20 100; do
    "$wavetrace" bench reorder --scene "builtin:$scene:8M" "${paged[@]}" --set "memory.budget=$budget%" \
        --json "$out/table3_${scene}8M_budget$budget.json" | tee "$out/table3_${scene}8M_budget$budget.txt"
  done
done
"$wavetrace" bench reorder --scene builtin:room:1M --accel bvh --size 320x240 --spp 4 --threads 2 \
    --json "$out/table3_room1M_incore.json" | tee "$out/table3_room1M_incore.txt"

for share in 0.000125 0.0005 0.02 0.08; do
  "$wavetrace" bench reorder --scene builtin:room:8M "${paged[@]}" --set memory.budget=20% --heuristics hph \
      --set "proxy.share=$share" --json "$out/table2_share$share.json" | tee "$out/table2_share$share.txt"
done
for buffer in 16384 65536 262144 1048576; do
  "$wavetrace" bench reorder --scene builtin:room:8M "${paged[@]}" --set memory.budget=20% --heuristics hph \
      --set "reorder.buffer_rays=$buffer" --set "render.rays_in_flight=$buffer" \
      --json "$out/table1_buffer$buffer.json" | tee "$out/table1_buffer$buffer.txt"
done
