#!/usr/bin/env python3
"""The billion-triangle table from bench/scale_suite.sh's files: per size and accelerator,
bytes per triangle of the structure, measured peak resident bytes per triangle (the OS's
VmHWM, everything included), build seconds, trace Mrays/s in the render and, at the sizes
benched, the median Mrays/s on 1M diffuse rays. Usage: scale_table.py OUT_DIR SIZE..."""
import json
import os
import sys

out, sizes = sys.argv[1], sys.argv[2:]
bench = {}
for size in ("8M", "64M"):
    path = os.path.join(out, f"bench_{size}.json")
    if os.path.exists(path):
        for result in json.load(open(path))["results"]:
            bench[(size, result["accel"])] = result["mrays_per_s"]
print(f"{'scene':<16} {'accel':<10} {'B/tri':>7} {'peak RSS B/tri':>15} {'build s':>8} {'render trace Mrays/s':>21} "
      f"{'1M diffuse Mrays/s':>19}")
for size in sizes:
    for accel in ("embree", "bvh", "raystrips", "hmq"):
        name = f"room_{size}_{accel}"
        stats_path = os.path.join(out, name + ".json")
        if not os.path.exists(stats_path):
            reason = open(os.path.join(out, name + ".txt")).read().strip().splitlines()[-1:] or ["no output"]
            print(f"{'room:' + size:<16} {accel:<10} does not fit: {reason[0][:150]}")
            continue
        stats = json.load(open(stats_path))
        triangles = stats["scene"]["triangles"]
        trace = next(s for s in stats["stages"] if s["name"] == "trace")
        diffuse = bench.get((size, accel))
        print(f"{'room:' + size:<16} {accel:<10} {stats['accel']['bytes_per_triangle']:>7.1f} "
              f"{stats['memory']['peak_rss_bytes'] / triangles:>15.1f} {stats['accel']['build_seconds']:>8.1f} "
              f"{trace['rays_in'] / stats['render']['seconds'] * 1e-6:>21.2f} "
              f"{(f'{diffuse:.2f}' if diffuse else '-'):>19}")
