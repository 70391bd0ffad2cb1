#!/usr/bin/env python3
"""Issue 17's table as Markdown, from bench/wide_suite.sh's JSON files: per scene and ray kind,
each layout's bytes per triangle (total and by part), Mrays/s, the ratio to default Embree (the
median of bench accel's rounds' ratios where the JSON has them) and
the hit agreement with robust Embree; then the leak counts.
Usage: bench/wide_table.py OUT_DIR"""
import glob
import json
import os
import sys

out = sys.argv[1] if len(sys.argv) > 1 else "out/wide"
order = ["room_1M", "room_8M", "bunny00_sub2", "diplodocus_sub2", "bear_sub2"]
print("| scene (triangles) | rays | accel | B/tri | hier | geom | other | Mrays/s | vs embree | hit agr. | prim. agr. |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for name in order:
    for rays in ["primary", "packets", "diffuse"]:
        path = os.path.join(out, f"{name}_{rays}.json")
        if not os.path.exists(path):
            continue
        report = json.load(open(path))
        first = report["results"][0]
        triangles = first["bytes"] / first["bytes_per_triangle"]
        for r in report["results"]:
            parts = {k: v / triangles for k, v in r["parts"].items()}
            print(f"| {name} ({triangles / 1e6:.2f}M) | {rays} | {r['accel']} | {r['bytes_per_triangle']:.1f} | "
                  f"{parts['hierarchy']:.1f} | {parts['geometry']:.1f} | {parts['other']:.1f} | {r['mrays_per_s']:.2f} | "
                  f"{r.get('vs_first') or r['mrays_per_s'] / first['mrays_per_s']:.2f}x | {100 * r['hit_agreement']:.4f}% | "
                  f"{100 * r['prim_agreement']:.2f}% |")
for path in sorted(glob.glob(os.path.join(out, "leak_*.json"))):
    report = json.load(open(path))
    print(f"\nLeaks, {os.path.basename(path)[5:-5]}, {report['results'][0]['rays']} rays each:",
          ", ".join(f"{r.get('label', r.get('accel'))} {r['escaped']}" for r in report["results"]))

# The same as one row per layout: bytes per triangle and the ratio to default Embree on primary
# rays, primary rays through intersect_coherent (packets where a layout has them) and diffuse rays.
print("\n| accel | " + " | ".join(f"{n}: B/tri, prim / packets / diff" for n in order) + " |")
print("|---|" + "---|" * len(order))
rows = {}
for name in order:
    cells = {}
    kinds = ["primary", "packets", "diffuse"]
    for rays in kinds:
        path = os.path.join(out, f"{name}_{rays}.json")
        if not os.path.exists(path):
            continue
        report = json.load(open(path))
        first = report["results"][0]
        for r in report["results"]:
            cell = cells.setdefault(r["accel"], [r["bytes_per_triangle"], None, None, None])
            cell[1 + kinds.index(rays)] = r["mrays_per_s"] / first["mrays_per_s"]
    for accel, (bpt, *ratios) in cells.items():
        rows.setdefault(accel, {})[name] = f"{bpt:.1f}, " + " / ".join("-" if x is None else f"{x:.2f}x" for x in ratios)
for accel, cells in rows.items():
    print(f"| {accel} | " + " | ".join(cells.get(n, "") for n in order) + " |")
