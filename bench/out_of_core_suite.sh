#!/usr/bin/env bash
# Table III of the reordering paper with real I/O (issue 32, item 4): one saved world rendered
# mapped whole (in core) and paged from disk at each budget, every heuristic with the memory
# and the disk ray buffer; bench/out_of_core_table.py turns the JSON into the Markdown table.
# Usage: bench/out_of_core_suite.sh WORLD.wtw OUT_DIR
# Settings (environment): SIZE (640x480), SPP (16), DEPTH (3), PAGES (page sizes in bytes, the
#   sweep of item 2: "131072"), BUDGETS ("24 10"),
#   HEURISTICS (none,paths,origin,origin_dir,hph,hph_origin,hph_dir; paths: no reordering, one
#   path at a time, the megakernel), BUFFERS ("memory disk"), PIXEL_ORDER (zcurve: the paper
#   generates camera rays along the Z-curve "for all the tests"; it is none's order),
#   LOW_HEURISTICS (the heuristics at budgets after the first; default HEURISTICS),
#   THREADS (2; paged renders keep more reads in flight with more threads than cores: 8 on
#   2 cores rendered room:64M 1.3x faster, docs/measurements.md), CURVE (morton).
# The paper's setting is a world of about 3,200 pages of 4 MB and over 10,000 rays a page: a
# saved builtin:room:64M hmq:width=8 world with its proxy at the defaults (hours on 2 cores).
set -euo pipefail
world=${1:?usage: bench/out_of_core_suite.sh WORLD.wtw OUT_DIR}
out=${2:-out/out_of_core}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
heuristics=${HEURISTICS:-none,paths,origin,origin_dir,hph,hph_origin,hph_dir}
common=(--scene "$world" --size "${SIZE:-640x480}" --spp "${SPP:-16}" --threads "${THREADS:-2}"
        --curve "${CURVE:-morton}" --set "render.max_depth=${DEPTH:-3}" --set "render.pixel_order=${PIXEL_ORDER:-zcurve}")
drop_caches() { sync; echo 3 > /proc/sys/vm/drop_caches 2>/dev/null || true; }

{ lscpu | grep "Model name" | tr -s " "; grep -o 'avx512[a-z_0-9]*' /proc/cpuinfo | sort -u | tr '\n' ' '; echo; } > "$out/cpu.txt"

"$wavetrace" bench reorder "${common[@]}" --heuristics "$heuristics" --json "$out/in_core.json" | tee "$out/in_core.txt"
first=1
for budget in ${BUDGETS:-24 10}; do
  list=$heuristics
  [[ $first == 1 ]] || list=${LOW_HEURISTICS:-$heuristics}
  first=0
  for page in ${PAGES:-131072}; do
    for buffer in ${BUFFERS:-memory disk}; do
      drop_caches
      "$wavetrace" bench reorder "${common[@]}" --heuristics "$list" --set memory.backing=file \
          --set "memory.budget=${budget}%" --set "memory.page_bytes=$page" --set "reorder.buffer=$buffer" \
          --json "$out/paged_${budget}pct_${buffer}_${page}B.json" | tee "$out/paged_${budget}pct_${buffer}_${page}B.txt"
    done
  done
done
/usr/bin/python3 bench/out_of_core_table.py "$out" | tee "$out/table.md"
