#!/usr/bin/env python3
"""Table III with real I/O as a Markdown table, from bench/world_suite.sh's reorder JSON files.
Usage: bench/world_table.py OUT_DIR"""
import glob
import json
import os
import re
import sys

out = sys.argv[1] if len(sys.argv) > 1 else "out/worlds"
runs = []
for path in glob.glob(os.path.join(out, "t3_*pct_*spp.json")):
    match = re.search(r"t3_(\d+)pct_(\d+)spp\.json$", path)
    if match is None:  # the in-memory baseline
        continue
    runs.append((-int(match.group(1)), int(match.group(2)), path))
for _, spp, path in sorted(runs):
    report = json.load(open(path))
    budget = re.search(r"pager (\S+)", report["memory"]).group(1)
    first = report["results"][0]
    for r in report["results"]:
        rays_per_page = r["rays_traced"] / max(report["page_count"], 1)
        print(f"| {budget}, {spp} spp ({rays_per_page:.0f}) | {r['heuristic']} | {r['disk_faults']} | {r['page_faults']} | "
              f"{first['disk_faults'] / r['disk_faults']:.2f}x | {r['disk_read_seconds']:.1f} | {r['render_seconds']:.1f} | "
              f"{first['render_seconds'] / r['render_seconds']:.2f}x |")
