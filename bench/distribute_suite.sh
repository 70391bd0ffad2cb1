#!/usr/bin/env bash
# Image-parallel renders against one process (issue 34's goal: 2 ranks x 1 thread at >= 0.95x
# the rays/s of one process x 2 threads): the same world, camera and settings, alternately
# alone and under mpirun, REPEAT times each; a table of medians and the ratio.
# Data mode (goal: each rank's peak resident <= 60% of one process's, rays/s >= 0.8x) needs a
# chunked world: RUNS="alone:1:2 image:2:1 data:2:1 data:4:1". The render's CPU (every rank's process,
# user and system, from the common start until all were done) shows what sharing costs in cores.
# Usage: bench/distribute_suite.sh SCENE OUT_DIR   (SCENE: a saved world .wtw, or builtin:...)
# Settings (environment): SIZE (640x480), SPP (8), DEPTH (5), HEURISTIC (hph), REPEAT (3),
#   RUNS ("alone:1:2 image:2:1"): MODE:RANKS:THREADS each, alone = without mpirun; data mode may
#   add :SHARE, its distribute.replicate, and :BALANCE, its distribute.balance (data:2:1:0.25:rays).
set -euo pipefail
scene=${1:?usage: bench/distribute_suite.sh SCENE OUT_DIR}
out=${2:-out/distribute}
mkdir -p "$out"
wavetrace=${WAVETRACE:-build/wavetrace}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # mpirun as root (CI, this machine)
common=(render "$scene" --size "${SIZE:-640x480}" --spp "${SPP:-8}" --set "reorder.heuristic=${HEURISTIC:-hph}"
        --set "render.max_depth=${DEPTH:-5}")

{ lscpu | grep "Model name" | tr -s " "; grep -o 'avx512[a-z_0-9]*' /proc/cpuinfo | sort -u | tr '\n' ' '; echo; } > "$out/cpu.txt"
cat "$out/cpu.txt"
for repeat in $(seq 1 "${REPEAT:-3}"); do
  for run in ${RUNS:-alone:1:2 image:2:1}; do
    IFS=: read -r mode ranks threads share balance <<< "$run"
    name="$out/${mode}_${ranks}x${threads}${share:+_r$share}${balance:+_$balance}_$repeat"
    if [[ $mode == alone ]]; then
      "$wavetrace" "${common[@]}" --threads "$threads" --out "$name.exr" --stats "$name.json" > "$name.txt" 2>&1
    else
      mpirun --oversubscribe -np "$ranks" "$wavetrace" "${common[@]}" --threads "$threads" \
          --set "distribute.mode=$mode" --set "distribute.replicate=${share:-0}" \
          --set "distribute.balance=${balance:-bytes}" \
          --out "$name.exr" --stats "$name.json" > "$name.txt" 2>&1
    fi
  done
done

python3 - "$out" ${RUNS:-alone:1:2 image:2:1} <<'PY'
import glob, json, statistics, sys, filecmp
out, runs = sys.argv[1], sys.argv[2:]
rows, base = [], None
print("| run | ranks x threads | render s (median) | rays traced | Mrays/s (median) | vs alone | render CPU core-s (median, all ranks) | CPU vs alone | peak resident GB a rank (most) | of alone's | while loading GB | bytes sent a ray | image |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
alone_peak = None
base_cpu = None
core_seconds = lambda cpu: cpu["user"] + cpu["system"]
for run in runs:
    mode, ranks, threads, *extra = run.split(":")
    share, balance = (extra + [None, None])[:2]
    tag = (f"_r{share}" if share else "") + (f"_{balance}" if balance else "")
    files = sorted(glob.glob(f"{out}/{mode}_{ranks}x{threads}{tag}_[0-9]*.json"))
    seconds, rates, peaks, loads, sent, cpus, traced = [], [], [], [], [], [], 0
    for path in files:
        stats = json.load(open(path))
        if "distribute" in stats:
            d = stats["distribute"]
            seconds.append(d["wall_seconds"]); traced = d["rays_traced"]
            peaks.append(max(r["peak_resident_bytes"] for r in d["per_rank"]) * 1e-9)
            loads.append(max(r.get("load_peak_resident_bytes", 0) for r in d["per_rank"]) * 1e-9)
            sent.append(sum(r.get("exchange", {}).get("bytes_sent", 0) for r in d["per_rank"]) / d["rays_traced"])
            cpus.append(sum(core_seconds(r["cpu_seconds"]) for r in d["per_rank"]))
        else:
            seconds.append(stats["render"]["seconds"])
            traced = next(s["rays_in"] for s in stats["stages"] if s["name"] == "trace")
            peaks.append(stats["memory"]["peak_rss_bytes"] * 1e-9)
            cpus.append(core_seconds(stats["render"]["cpu_seconds"]))
        rates.append(traced / seconds[-1] * 1e-6)
    rate = statistics.median(rates)
    base = base or rate
    first = f"{out}/{runs[0].split(':')[0]}_{runs[0].split(':')[1]}x{runs[0].split(':')[2]}_1.exr"
    identical = all(filecmp.cmp(p.replace(".json", ".exr"), first, shallow=False) for p in files)
    alone_peak = alone_peak or max(peaks)
    cpu = statistics.median(cpus)
    base_cpu = base_cpu or cpu
    label = mode + "".join(f", {k} {v}" for k, v in (("replicate", share), ("balance", balance)) if v)
    print(f"| {label} | {ranks} x {threads} | {statistics.median(seconds):.3f} | {traced:,} | {rate:.3f} | "
          f"{rate / base:.3f} | {cpu:.2f} | {cpu / base_cpu:.2f} | {max(peaks):.2f} | {max(peaks) / alone_peak:.0%} | "
          f"{max(loads) if loads and max(loads) > 0 else float('nan'):.2f} | "
          f"{statistics.median(sent) if sent else 0:.1f} | {'identical' if identical else 'DIFFERS'} |")
PY
