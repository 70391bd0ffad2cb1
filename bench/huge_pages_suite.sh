#!/bin/bash
# Huge pages at scale (per-ray issue, item 3): builtin:room at 8M and 64M rendered with
# hmq:width=8 (320x240, 8 spp, depth 3, 2 threads) with large arrays advised onto 2 MiB pages
# (the default) and without (WAVETRACE_HUGE_PAGES=0), Embree beside; prints the trace stage's
# Mrays/s per thread and the most AnonHugePages the process held (sampled every 0.5 s), so
# that the A/B shows the advice took. Usage: bench/huge_pages_suite.sh [build/wavetrace] [out]
set -eu
wavetrace=${1:-build/wavetrace}
out=${2:-out/huge_pages}
mkdir -p "$out"
for size in 8M 64M; do
  for advised in 1 0; do
    accels="hmq:width=8"
    [ "$advised" = 1 ] && accels="$accels embree"  # Embree advises its own memory either way
    for accel in $accels; do
      name="room_${size}_${accel%%:*}_huge${advised}"
      WAVETRACE_HUGE_PAGES=$advised "$wavetrace" render "builtin:room:$size" --accel "$accel" --size 320x240 --spp 8 \
          --threads 2 --set render.max_depth=3 --stats "$out/$name.json" --out "$out/$name.exr" > "$out/$name.log" 2>&1 &
      pid=$!
      huge_kb=0
      while kill -0 "$pid" 2> /dev/null; do
        now=$(awk '/AnonHugePages/ {print $2}' "/proc/$pid/smaps_rollup" 2> /dev/null || true)
        if [ -n "$now" ] && [ "$now" -gt "$huge_kb" ]; then huge_kb=$now; fi
        sleep 0.5
      done
      wait "$pid"
      /usr/bin/python3 - "$out/$name.json" "$name" "$huge_kb" <<'PY'
import json, sys
stats = json.load(open(sys.argv[1]))
trace = next(stage for stage in stats["stages"] if stage["name"] == "trace")
print(f"{sys.argv[2]:<28} trace {trace['mrays_per_s']:.3f} Mrays/s/thread over {trace['rays_in']} rays, "
      f"isa {stats['accel']['isa']}, peak {stats['memory']['peak_rss_bytes'] / 1e9:.2f} GB, "
      f"AnonHugePages up to {int(sys.argv[3]) // 1024} MB")
PY
    done
  done
done
