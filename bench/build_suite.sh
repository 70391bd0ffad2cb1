#!/usr/bin/env bash
# The build-speed issue's table: `wavetrace build` of each accelerator on each scene, one
# after another in one run (the machine's noise falls on all alike), REPEAT rounds, with the
# build's phases (accel.build_phases) and its peak resident memory from the OS.
#   SCENES="builtin:room:8M builtin:room:64M" ACCELS="embree hmq:width=8 ..." REPEAT=3 THREADS=2
# Usage: bench/build_suite.sh OUT_DIR   then   /usr/bin/python3 bench/build_table.py OUT_DIR
set -euo pipefail
out=${1:-out/build}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
scenes=${SCENES:-"builtin:room:8M builtin:room:64M"}
accels=${ACCELS:-"embree hmq:width=8 bvh:width=8 raystrips:width=8"}
repeat=${REPEAT:-3}
threads=${THREADS:-2}
grep -m1 "model name" /proc/cpuinfo > "$out/cpu.txt"
grep -m1 -o "avx512[a-z_0-9]*" /proc/cpuinfo | sort -u | tr '\n' ' ' >> "$out/cpu.txt" || true
for round in $(seq 1 "$repeat"); do
  for scene in $scenes; do
    for accel in $accels; do
      name="$(echo "${scene#builtin:}_${accel}" | tr ':=' '__')_r${round}"
      /usr/bin/time -f "%M %e" -o "$out/$name.time" "$wavetrace" build "$scene" --accel "$accel" --threads "$threads" \
          --out "$out/build.wtw" --stats "$out/$name.json" > "$out/$name.log"
      rm -f "$out/build.wtw"
      echo "$accel" > "$out/$name.accel"
      echo "$name: $(grep -E '^scene ' "$out/$name.log")"
    done
  done
done
