#!/usr/bin/env python3
"""Table III with real I/O as Markdown, from bench/out_of_core_suite.sh's JSON: every paged run
beside the same heuristic's render of the world mapped whole (the fraction of in-core speed),
its reads and time against none's and against paths' (one path at a time, the paper's renderer
without reordering), then where the trace's reads went (faults by part of the world file).
Usage: bench/out_of_core_table.py OUT_DIR"""
import glob
import json
import os
import re
import sys

out = sys.argv[1] if len(sys.argv) > 1 else "out/out_of_core"
in_core = json.load(open(os.path.join(out, "in_core.json")))
in_core_rate = {r["heuristic"]: r["rays_traced"] / r["render_seconds"] for r in in_core["results"]}
cpu = open(os.path.join(out, "cpu.txt")).read().strip().replace("\n", "; ") if os.path.exists(
    os.path.join(out, "cpu.txt")) else "(cpu not recorded)"

runs = []
for path in glob.glob(os.path.join(out, "paged_*pct_*_*B.json")):
    match = re.search(r"paged_(\d+)pct_([a-z]+)_(\d+)B\.json$", path)
    budget, buffer, page = int(match.group(1)), match.group(2), int(match.group(3))
    runs.append((-budget, buffer != "memory", page, buffer, budget, path))

print(f"{in_core['scene']['source']}: {in_core['scene']['triangles']} triangles, {in_core['image']}, "
      f"{in_core['accel']}, {in_core['threads']} threads; {cpu}")
print()
print("| budget | buffer | page KiB | heuristic | rays traced | rays/page | real reads | MB read | read s | wait s | "
      "pages/1k rays | render s | Mrays/s | of in-core | reads vs none | time vs none | reads vs paths | time vs paths | "
      "identical |")
print("| --- | --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: "
      "| --- |")
parts = []
for _, _, page, buffer, budget, path in sorted(runs):
    report = json.load(open(path))
    pages = max(report["page_count"], 1)
    baseline = {name: next((r for r in report["results"] if r["heuristic"] == name), None) for name in ("none", "paths")}
    for r in report["results"]:
        rate = r["rays_traced"] / r["render_seconds"]
        versus = lambda name, key: f"{baseline[name][key] / r[key]:.2f}x" if baseline[name] and r[key] else "-"
        pages_1k = r.get("disk_pages_per_1000_rays")
        pages_1k = f"{pages_1k:.1f}" if pages_1k is not None else "-"
        print(f"| {budget}% | {buffer} | {page >> 10:,} | {r['heuristic']} | {r['rays_traced']:,} | {r['rays_traced'] / pages:,.0f} | "
              f"{r['disk_faults']:,} | {r['disk_bytes_read'] / 1e6:,.0f} | {r['disk_read_seconds']:.1f} | "
              f"{r['disk_wait_seconds']:.1f} | {pages_1k} | {r['render_seconds']:.1f} | {rate / 1e6:.3f} | "
              f"{100 * rate / in_core_rate[r['heuristic']]:.1f}% | {versus('none', 'disk_faults')} | "
              f"{versus('none', 'render_seconds')} | {versus('paths', 'disk_faults')} | {versus('paths', 'render_seconds')} | "
              f"{'yes' if r['image_identical'] else 'NO'} |")
        parts.append((budget, buffer, page, r["heuristic"], r.get("disk_faults_by_part", {}), r["disk_faults"]))
print()
print("In core (mapped whole): " + ", ".join(
    f"{r['heuristic']} {r['render_seconds']:.2f} s ({in_core_rate[r['heuristic']] / 1e6:.3f} Mrays/s)"
    for r in in_core["results"]))
print()
names = sorted({name for *_, by_part, _ in parts for name in by_part})
print("| budget | buffer | page KiB | heuristic | " + " | ".join(names) + " |")
print("| --- | --- | ---: | --- | " + " | ".join("---:" for _ in names) + " |")
for budget, buffer, page, heuristic, by_part, faults in parts:
    cells = [f"{100 * by_part.get(n, 0) / max(faults, 1):.1f}%" for n in names]
    print(f"| {budget}% | {buffer} | {page >> 10:,} | {heuristic} | " + " | ".join(cells) + " |")
