#!/usr/bin/env bash
# The world-file issue's measurements.
#   1. builtin:room:1G with hmq built once into a world file, then (page cache dropped) rendered
#      from it: build against load seconds, peak resident memory of each, file bytes/triangle.
#   2. Table III with real I/O: builtin:room:8M (hmq, with the proxy) saved, then every reorder
#      heuristic rendered with the world paged from disk (O_DIRECT, 128 KiB pages, a 1M-ray
#      buffer) at budgets 20% and 5%, and an spp sweep (rays per page) at 5%.
# Usage: bench/world_suite.sh OUT_DIR [--skip-1g]   (the 1G build takes ~25 minutes, the rest ~40)
set -euo pipefail
out=${1:-out/worlds}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
drop_caches() { sync; echo 3 > /proc/sys/vm/drop_caches 2>/dev/null || echo "(page cache not dropped: not root)"; }

if [[ "${2:-}" != "--skip-1g" ]]; then
  /usr/bin/time -f "%M KB %e s" "$wavetrace" build builtin:room:1G --accel hmq --out "$out/room1G_hmq.wtw" \
      --stats "$out/room1G_build.json" > "$out/room1G_build.log" 2>&1
  drop_caches
  /usr/bin/time -f "%M KB %e s" "$wavetrace" render "$out/room1G_hmq.wtw" --size 640x480 --spp 4 \
      --set render.max_depth=3 --out "$out/room1G_from_world.exr" --stats "$out/room1G_from_world.json" \
      > "$out/room1G_render.log" 2>&1
fi

"$wavetrace" build builtin:room:8M --accel hmq --proxy --out "$out/room8M_hmq.wtw" --stats "$out/room8M_build.json"
common=(--scene "$out/room8M_hmq.wtw" --size 320x240 --threads 2 --set render.max_depth=3 --set memory.backing=file
        --set memory.page_bytes=131072 --set reorder.buffer_rays=1048576 --set render.rays_in_flight=1048576)
for budget in 20 5; do
  "$wavetrace" bench reorder "${common[@]}" --spp 4 --set "memory.budget=${budget}%" \
      --json "$out/t3_${budget}pct_4spp.json" | tee "$out/t3_${budget}pct_4spp.txt"
done
for spp in 1 8; do
  "$wavetrace" bench reorder "${common[@]}" --spp "$spp" --heuristics none,hph,hph_origin --set memory.budget=5% \
      --json "$out/t3_5pct_${spp}spp.json" | tee "$out/t3_5pct_${spp}spp.txt"
done
/usr/bin/python3 bench/world_table.py "$out"
