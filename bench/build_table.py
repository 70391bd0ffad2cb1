#!/usr/bin/python3
"""The build-speed table from bench/build_suite.sh's runs: per scene and accelerator, the
median over rounds of scene (generation) and build seconds, triangles a second with the
scene's generation counted, the ratio to Embree's in the same rounds, peak resident memory
(the OS's VmHWM, /usr/bin/time %M) and the median of each build phase."""
import collections, glob, json, os, re, statistics, sys

out = sys.argv[1] if len(sys.argv) > 1 else "out/build"
runs = collections.defaultdict(list)
for path in sorted(glob.glob(os.path.join(out, "*_r*.json"))):
    key = re.sub(r"_r\d+\.json$", "", os.path.basename(path))
    stats = json.load(open(path))
    peak_kb, wall = open(path[:-5] + ".time").read().split()[-2:]
    stats["accel"] = open(path[:-5] + ".accel").read().strip()  # the spec asked for, not the type built
    runs[key].append((stats, int(peak_kb) * 1024, float(wall)))

def median(values):
    return statistics.median(values) if values else float("nan")

rows = {}
for key, items in runs.items():
    stats = items[0][0]
    scene_s = median([s["scene_seconds"] for s, _, _ in items])
    build_s = median([s["build_seconds"] for s, _, _ in items])
    total = median([s["scene_seconds"] + s["build_seconds"] for s, _, _ in items])
    phases = collections.defaultdict(list)
    for s, _, _ in items:
        for phase, seconds in s.get("build_phases", {}).items():
            phases[phase].append(seconds)
    rows[key] = dict(scene=stats["scene"]["source"], accel=stats["accel"], triangles=stats["scene"]["triangles"],
                     rounds=len(items), scene_s=scene_s, build_s=build_s, total=total,
                     peak=median([p for _, p, _ in items]), phases={k: median(v) for k, v in phases.items()})

print(open(os.path.join(out, "cpu.txt")).read().strip() if os.path.exists(os.path.join(out, "cpu.txt")) else "")
print("| scene | accel | rounds | scene s | build s | scene + build s | M tri/s | vs Embree (scene + build) | vs Embree (build) | peak GB |")
print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
for key in sorted(rows, key=lambda k: (rows[k]["triangles"], rows[k]["accel"] != "embree", rows[k]["accel"])):
    r = rows[key]
    ref = next((x for x in rows.values() if x["scene"] == r["scene"] and x["accel"] == "embree"), None)
    vs = f"{ref['total'] / r['total']:.2f}x" if ref else "-"
    vs_build = f"{ref['build_s'] / r['build_s']:.2f}x" if ref else "-"
    print(f"| {r['scene']} | {r['accel']} | {r['rounds']} | {r['scene_s']:.2f} | {r['build_s']:.2f} | {r['total']:.2f} | "
          f"{r['triangles'] / r['total'] * 1e-6:.2f} | {vs} | {vs_build} | {r['peak'] * 1e-9:.2f} |")
print()
print("Phases (median seconds; a chunked build's own phases are wall seconds, chunk.* thread-seconds summed over chunks):")
for key in sorted(rows, key=lambda k: (rows[k]["triangles"], rows[k]["accel"])):
    r = rows[key]
    print(f"- {r['scene']} {r['accel']}: " + ", ".join(f"{k} {v:.2f}" for k, v in r["phases"].items()))
