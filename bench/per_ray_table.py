#!/usr/bin/env python3
"""Issue 33's table as Markdown, from bench/per_ray_suite.sh's JSON files: per scene and ray
kind, each accelerator's Mrays/s, the median of its rounds' ratios to the first (Embree's
native kernels) with their range, and its bytes a triangle; then each of the issue's goals
checked row by row from those figures.
Usage: bench/per_ray_table.py OUT_DIR"""
import json
import os
import sys

SCENES = [("room_1M", "room:1M"), ("room_8M", "room:8M"), ("bunny00_sub2", "bunny00 x2"),
          ("diplodocus_sub2", "diplodocus x2"), ("bear_sub2", "bear x2")]
RAYS = [("primary", "camera"), ("diffuse", "diffuse")]
# (accelerator, ray kinds, least ratio to Embree, most bytes a triangle or None): issue 33's goals.
GOALS = [("bvh:width=8", ("primary", "diffuse"), 0.9, None),
         ("hmq:width=8", ("diffuse",), 0.8, 8.0),
         ("raystrips:width=8", ("diffuse",), 0.6, 16.0)]


def ratio(result):
    """The rounds' median ratio to the first; a JSON of one accelerator at a time has none."""
    return result.get("vs_first", 0.0), result.get("vs_first_runs") or []


def load(out):
    rows = []
    for name, label in SCENES:
        for rays, ray_label in RAYS:
            path = os.path.join(out, f"{name}_{rays}.json")
            if os.path.exists(path):
                with open(path) as f:
                    rows.append((label, rays, ray_label, json.load(f)))
    return rows


def table(rows):
    if not rows:
        return "no bench JSON found\n"
    accels = [r["accel"] for r in rows[0][3]["results"]]
    lines = ["| scene, rays | " + " | ".join(accels) + " |", "| --- |" + " ---: |" * len(accels)]
    for label, _, ray_label, doc in rows:
        cells = []
        for r in doc["results"]:
            median, runs = ratio(r)
            spread = f", {min(runs):.2f}-{max(runs):.2f}" if runs else ""
            cells.append(f"{r['mrays_per_s']:.2f} ({median:.2f}x{spread}; {r['bytes_per_triangle']:.1f} B/tri)")
        lines.append(f"| {label}, {ray_label} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def goals(rows):
    lines = []
    for accel, kinds, least, most_bytes in GOALS:
        misses, checked = [], 0
        for label, rays, ray_label, doc in rows:
            if rays not in kinds:
                continue
            result = next((r for r in doc["results"] if r["accel"] == accel), None)
            if result is None:
                continue
            checked += 1
            median, _ = ratio(result)
            if median < least or (most_bytes is not None and result["bytes_per_triangle"] > most_bytes):
                misses.append(f"{label} {ray_label} {median:.2f}x, {result['bytes_per_triangle']:.1f} B/tri")
        bound = f">= {least}x Embree" + (f" at <= {most_bytes:g} B/tri" if most_bytes else "")
        if checked == 0:
            lines.append(f"- {accel} {bound} on {'/'.join(kinds)} rays: not measured")
        elif misses:
            lines.append(f"- {accel} {bound} on {'/'.join(kinds)} rays: not met on {len(misses)} of {checked} rows "
                         f"({'; '.join(misses)})")
        else:
            lines.append(f"- {accel} {bound} on {'/'.join(kinds)} rays: met on all {checked} rows")
    return "\n".join(lines) + "\n"


def main(out):
    rows = load(out)
    cpu = os.path.join(out, "cpu.txt")
    if os.path.exists(cpu):
        with open(cpu) as f:
            sys.stdout.write(f.read().strip() + "\n\n")
    sys.stdout.write(table(rows) + "\n" + goals(rows))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/per_ray")
