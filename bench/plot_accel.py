#!/usr/bin/python3
"""Charts from `wavetrace bench accel --json` files: speed (Mrays/s, median) and memory
(bytes per triangle, split into hierarchy / geometry / other) per accelerator, one group
of bars per run. Usage: bench/plot_accel.py OUT.png RESULT.json [RESULT.json ...]"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    output, paths = sys.argv[1], sys.argv[2:]
    runs = []
    for path in paths:
        with open(path) as file:
            runs.append(json.load(file))
    accels = []
    for run in runs:
        for result in run["results"]:
            if result["accel"] not in accels:
                accels.append(result["accel"])

    figure, (speed, memory) = plt.subplots(1, 2, figsize=(6 + 1.5 * len(runs), 4.5))
    width = 0.8 / len(accels)
    for index, accel in enumerate(accels):
        values = []
        for run in runs:
            match = [r for r in run["results"] if r["accel"] == accel]
            values.append(match[0]["mrays_per_s"] if match else 0.0)
        speed.bar([r + index * width for r in range(len(runs))], values, width, label=accel)
    speed.set_xticks([r + 0.4 - width / 2 for r in range(len(runs))])
    speed.set_xticklabels(
        [f'{run["scene"]["source"].replace("builtin:", "")}\n{run["rays"]["kind"]}, {run["threads"]} thr' for run in runs],
        fontsize=8)
    speed.set_ylabel("Mrays/s (median)")
    speed.set_title("trace speed, same rays")
    speed.legend(fontsize=7)

    first = runs[0]
    bottoms = [0.0] * len(first["results"])
    triangles = first["scene"]["triangles"]
    for part in ("hierarchy", "geometry", "other"):
        values = [r["parts"][part] / triangles for r in first["results"]]
        memory.bar(range(len(values)), values, bottom=bottoms, label=part)
        bottoms = [b + v for b, v in zip(bottoms, values)]
    memory.set_xticks(range(len(first["results"])))
    memory.set_xticklabels([r["accel"] for r in first["results"]], rotation=30, ha="right", fontsize=7)
    memory.set_ylabel("bytes / triangle")
    memory.set_title(first["scene"]["source"])
    memory.legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(output, dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main())
