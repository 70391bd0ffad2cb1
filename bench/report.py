#!/usr/bin/python3
"""Charts and OUT/report.md from the JSON files of `wavetrace bench report` (OUT/data/).

Each file is recognised by its content (bench accel, image, reorder, leak; render stats), so
`bench report --from` takes any earlier ones. Runs with Debian's interpreter, which has
matplotlib: /usr/bin/python3 bench/report.py OUT"""
import json
import math
import re
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

# Settings that let rays through shared edges (bench leak): left out of "watertight".
LEAKY = ("embree", "embree:mode=compact")
WATERTIGHT_NOTE = "default and compact Embree let rays through shared edges (see the leaks row)"


def kind_of(doc):
    if "stages" in doc and "accel" in doc and "image" in doc:
        return "render"
    if "file_bytes" in doc:
        return "build"
    results = doc.get("results") or [{}]
    first = results[0]
    if "heuristic" in first:
        return "reorder"
    if "escaped" in first:
        return "leak"
    if "rmse" in first:
        return "image"
    if "mrays_per_s" in first:
        return "accel"
    return "unknown"


def load(out):
    docs = {}
    for path in sorted((out / "data").glob("*.json")):
        if path.name == "runs.json":
            continue
        with open(path) as file:
            docs[path.stem] = json.load(file)
    with open(out / "data" / "runs.json") as file:
        runs = json.load(file)
    return docs, runs


def scene_name(doc):
    return doc["scene"]["source"].replace("builtin:", "")


def scene_label(stem):
    """The scene part of a matrix run's name (accel_room_primary -> room); a file named any
    other way (bench accel --json a.json, given with --from) is its own label."""
    parts = stem.split("_")
    return parts[1] if len(parts) > 1 else stem


def base_spec(label):
    """'auto:memory_budget=... (hmq:width=8:epsilon=0.01)' -> 'auto:memory_budget=...'."""
    return label.split(" (")[0]


def short(label):
    label = re.sub(r"memory_budget=(\d+)", lambda m: f"budget={int(m.group(1)) / 1e6:.0f}MB", label)
    return re.sub(r":chunk_triangles=\d+", ":chunked", label)


def pareto_front(points):
    """Points (bytes, speed, label) no other beats on both: fewer bytes and more speed."""
    front = []
    for p in sorted(points, key=lambda p: (p[0], -p[1])):
        if not front or p[1] > front[-1][1]:
            front.append(p)
    return front


def chart_pareto(name, doc, out):
    triangles = doc["scene"]["triangles"]
    points = [(r["bytes"] / triangles, r["mrays_per_s"], r["accel"]) for r in doc["results"]]
    fixed = [p for p in points if not p[2].startswith("auto")]
    front = pareto_front(fixed)
    figure, axes = plt.subplots(figsize=(7.5, 5))
    for bpt, speed, label in fixed:
        on_front = any(label == f[2] for f in front)
        axes.scatter(bpt, speed, s=36, color="tab:blue" if on_front else "tab:gray", zorder=3)
        axes.annotate(short(label), (bpt, speed), fontsize=7, xytext=(4, 3), textcoords="offset points")
    axes.step([f[0] for f in front], [f[1] for f in front], where="post", color="tab:blue", lw=1,
              label="Pareto front (fewer bytes, more speed)")
    for bpt, speed, label in points:
        if label.startswith("auto"):
            axes.scatter(bpt, speed, marker="*", s=140, color="tab:red", zorder=4)
            axes.annotate(short(label), (bpt, speed), fontsize=7, color="tab:red", xytext=(4, -10),
                          textcoords="offset points")
    axes.scatter([], [], marker="*", s=100, color="tab:red", label="accel.type = auto (its choice)")
    axes.set_xscale("log")
    # The values a reader looks for, not only the decades: 2, 5, 10, 20, 50, 100 ...
    low, high = axes.get_xlim()
    ticks = [t for t in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000) if low <= t <= high]
    axes.xaxis.set_major_locator(matplotlib.ticker.FixedLocator(ticks))
    axes.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    axes.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes.set_xlabel("bytes per triangle (structure, and the mesh it reads in place)")
    axes.set_ylabel("Mrays/s (median)")
    axes.set_title(f"{scene_name(doc)}: {doc['rays']['kind']} rays, {doc['threads']} threads")
    # Below the axes, where it can hide no point.
    axes.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, frameon=False)
    figure.tight_layout()
    figure.savefig(out / f"{name}.png", dpi=110, bbox_inches="tight")
    plt.close(figure)
    return front


def chart_hmq_error(name, doc, out):
    results = sorted((r for r in doc["results"] if r.get("vertex_error_max") is not None),
                     key=lambda r: r["vertex_error_max"])
    reference = next((r for r in doc["results"] if r["accel"].startswith("embree")), None)
    figure, (bound, speed) = plt.subplots(1, 2, figsize=(10, 4.2))
    xs = [r["vertex_error_max"] for r in results]
    ys = [r["surface_error_max"] for r in results]
    bound.loglog(xs, ys, "o", color="tab:blue", label="largest hit-point error, measured")
    span = [min(xs + ys) * 0.5, max(xs + ys) * 2]
    bound.loglog(span, span, "--", color="gray", lw=1, label="the bound (largest vertex move)")
    for r in results:
        bound.annotate(short(r["accel"]).replace("hmq:width=8:", ""), (r["vertex_error_max"], r["surface_error_max"]),
                       fontsize=7, xytext=(4, -8), textcoords="offset points")
    bound.set_xlabel("bound: largest vertex move (scene units)")
    bound.set_ylabel("hit point's distance from the mesh's triangle")
    bound.set_title(f"HMQ error against its bound, {scene_name(doc)}")
    bound.legend(fontsize=7)
    triangles = doc["scene"]["triangles"]
    speed.semilogx(xs, [r["mrays_per_s"] for r in results], "o-", color="tab:green", label="Mrays/s")
    if reference:
        speed.axhline(reference["mrays_per_s"], color="tab:green", ls=":", lw=1, label=f"{reference['accel']} Mrays/s")
    twin = speed.twinx()
    twin.semilogx(xs, [r["bytes"] / triangles for r in results], "s--", color="tab:purple", label="bytes/triangle")
    speed.set_xlabel("bound: largest vertex move (scene units)")
    speed.set_ylabel("Mrays/s (median)")
    twin.set_ylabel("bytes per triangle")
    speed.set_title("speed and size against the bound")
    lines = speed.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    speed.legend(lines[0] + more[0], lines[1] + more[1], fontsize=7, loc="lower right")
    figure.tight_layout()
    figure.savefig(out / f"{name}.png", dpi=110)
    plt.close(figure)


def chart_image(name, doc, out):
    noise = [r for r in doc["results"] if r.get("noise_floor")]
    lossy = [r for r in doc["results"][1:] if not r.get("noise_floor")]
    figure, axes = plt.subplots(figsize=(7.5, 4.5))
    axes.scatter([r["closest_mrays_per_s"] for r in lossy], [r["rmse"] for r in lossy], color="tab:blue", zorder=3)
    for r in lossy:
        axes.annotate(short(r["accel"]).replace("hmq:width=8:", ""), (r["closest_mrays_per_s"], r["rmse"]), fontsize=7,
                      xytext=(4, 3), textcoords="offset points")
    for r in noise:
        axes.axhline(r["rmse"], color="tab:red", ls="--", lw=1,
                     label=f"Monte Carlo noise: {doc['reference']} against itself with the next seed")
    axes.set_yscale("symlog", linthresh=1e-5)
    axes.set_xlabel("closest-hit Mrays/s in the render")
    axes.set_ylabel(f"image RMSE against {doc['reference']}")
    axes.set_title(f"HMQ's image error, {scene_name(doc)} ({doc['image']})")
    axes.legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(out / f"{name}.png", dpi=110)
    plt.close(figure)


def budget_of(doc):
    match = re.match(r"pager (\d+)%", doc.get("memory", ""))
    return int(match.group(1)) if match else None


def chart_faults(name, docs, out):
    figure, axes = plt.subplots(figsize=(7.5, 4.5))
    series = {}
    for doc in docs:
        budget = budget_of(doc)
        real = "real" in doc["memory"]
        for r in doc["results"]:
            if r.get("page_faults") is not None and not real:
                series.setdefault((r["heuristic"], "simulated"), []).append((budget, r["page_faults"]))
            if r.get("disk_faults") is not None:
                series.setdefault((r["heuristic"], "real"), []).append((budget, r["disk_faults"]))
    colors = {}
    for (heuristic, kind), values in sorted(series.items()):
        values.sort()
        color = colors.setdefault(heuristic, f"C{len(colors)}")
        axes.plot([v[0] for v in values], [max(v[1], 0.5) for v in values], "o-" if kind == "simulated" else "s--",
                  color=color, label=f"{heuristic} ({kind})")
    axes.set_yscale("log")
    axes.set_xlabel("page pool budget (% of the world's pages)")
    axes.set_ylabel("page faults")
    axes.set_title(f"page faults against budget per reorder heuristic, {scene_name(docs[0])}")
    axes.legend(fontsize=7, ncol=2)
    figure.tight_layout()
    figure.savefig(out / f"{name}.png", dpi=110)
    plt.close(figure)
    return series


def chart_stages(name, docs, out):
    figure, axes = plt.subplots(figsize=(7.5, 3.2 + 0.3 * len(docs)))
    labels = []
    names = []
    for doc in docs.values():
        for stage in doc["stages"]:
            if stage["name"] not in names:
                names.append(stage["name"])
    for row, (stem, doc) in enumerate(docs.items()):
        total = sum(stage["seconds"] for stage in doc["stages"]) or 1.0
        left = 0.0
        for stage in doc["stages"]:
            share = stage["seconds"] / total
            axes.barh(row, share, left=left, color=f"C{names.index(stage['name'])}",
                      label=stage["name"] if row == 0 or stage["name"] not in [s["name"] for s in
                                                                                list(docs.values())[0]["stages"]] else None)
            if share > 0.06:
                axes.text(left + share / 2, row, f"{100 * share:.0f}%", ha="center", va="center", fontsize=7, color="white")
            left += share
        labels.append(f"{stem.replace('stages_', 'reorder ')}\n{doc['accel']['type']}")
    axes.set_yticks(range(len(labels)))
    axes.set_yticklabels(labels, fontsize=8)
    axes.set_xlabel("share of the stages' thread-seconds")
    axes.set_title(f"where a render's time goes, {scene_name(list(docs.values())[0])}")
    axes.legend(fontsize=7, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.25))
    figure.tight_layout()
    figure.savefig(out / f"{name}.png", dpi=110)
    plt.close(figure)


def result(doc, spec):
    return next((r for r in doc["results"] if base_spec(r["accel"]) == spec), None)


def ratio(doc, spec, against="embree:mode=robust"):
    r, base = result(doc, spec), result(doc, against)
    return r["mrays_per_s"] / base["mrays_per_s"] if r and base and base["mrays_per_s"] > 0 else float("nan")


def footprint(r):
    """The most a setting held at once, measured: its structure's bytes, or its build's peak
    resident memory above where it began (the OS's VmHWM) plus, for a type that reads the mesh
    in place, the mesh's bytes it counts (resident before the build began), whichever is more."""
    in_place = 0 if base_spec(r["accel"]).startswith(("hmq", "raystrips")) else r["parts"]["geometry"]
    return max(r["bytes"], (r.get("build_peak_rss_above_start_bytes") or 0) + in_place)


def footprint_runs(docs, commands):
    """(stem, scene label, --accel spec) of each footprint run whose stats are present."""
    for stem, run in commands.items():
        if run.get("section") != "footprint" or stem not in docs:
            continue
        words = run["command"].split()
        yield stem, scene_label(stem), words[words.index("--accel") + 1].strip("'")


def render_peaks(docs, commands):
    """(scene label, --accel spec) -> the render's peak resident bytes, from the footprint runs."""
    return {(label, spec): docs[stem]["memory"]["peak_rss_bytes"] for stem, label, spec in footprint_runs(docs, commands)}


def candidate_setting(spec, candidate, auto_spec):
    """The --accel setting a candidate of `auto_spec` stands for: built in that auto's chunks
    when the choice would chunk it ('raystrips:width=8' -> 'raystrips:width=8:chunk_triangles=N')."""
    chunk = re.search(r":chunk_triangles=\d+", auto_spec)
    return spec + (chunk.group(0) if chunk and candidate.get("chunked") else "")


def estimate_rows(docs, commands, peaks):
    """Auto's estimate of every candidate's render peak against that setting's measured peak:
    the candidates of the footprint runs of auto (each render's own estimates, streamed as it
    streams), as a whole build under the machine's budget and in the tight autos' chunks."""
    rows = {}
    for stem, label, spec in footprint_runs(docs, commands):
        choice = docs[stem].get("accel", {}).get("auto")
        if not spec.startswith("auto") or not choice:
            continue
        for candidate in choice["candidates"]:
            # HMQ's footprint is measured at its default grid; the bound changes bytes little.
            setting = candidate_setting(re.sub(r":epsilon=[^:]*", "", candidate["spec"]), candidate, spec)
            peak = peaks.get((label, setting))
            if peak is not None:
                rows[(label, setting)] = (candidate["estimated_bytes"], peak)
    return rows


def auto_rows(name, doc, peaks):
    """Each auto setting of an accel run against the fastest setting that fits its budget and
    meets its error bound (measured footprint, measured hit-point error) and is not leaky.
    The footprint is a render's peak resident memory (the footprint runs) where there is one;
    else (earlier JSON) the bench's bytes or build peak, with the whole mesh for compact types."""
    rows = []
    triangles = doc["scene"]["triangles"]
    label = scene_label(name)
    for r in doc["results"]:
        choice = r.get("auto")
        if not choice:
            continue
        budget, bound = choice["budget_bytes"], choice["max_error"]
        measured_peaks = any(key[0] == label for key in peaks)
        fitting = []
        for other in doc["results"]:
            spec = base_spec(other["accel"])
            if other.get("auto") or spec in LEAKY:
                continue
            if measured_peaks:
                peak = peaks.get((label, spec))
                if peak is None or peak > budget:
                    continue
            else:
                mesh = choice["mesh_bytes_per_triangle"] * triangles if spec.startswith(("hmq", "raystrips")) else 0
                if footprint(other) + mesh > budget - choice["process_bytes"]:
                    continue
            error = other.get("surface_error_max")
            if error is not None and not error <= bound:
                continue
            fitting.append(other)
        best = max(fitting, key=lambda o: o["mrays_per_s"], default=None)
        chosen = next((c for c in choice["candidates"] if c["chosen"]), {})
        chosen_setting = candidate_setting(choice["chosen"], chosen, base_spec(r["accel"]))
        peak = peaks.get((label, base_spec(r["accel"])), float("nan"))
        rows.append({
            "run": name, "scene": scene_name(doc), "rays": doc["rays"]["kind"], "auto": short(base_spec(r["accel"])),
            "budget": budget, "bound": bound, "chosen": choice["chosen"], "speed": r["mrays_per_s"],
            "estimate": chosen.get("estimated_bytes", float("nan")),
            "peak": peak, "fits": peak <= budget if peak == peak else None,
            # auto took the very setting it is measured against: their runs differ by the
            # machine's noise alone, so the choice is the fastest that fits by construction.
            "same_setting": best is not None and chosen_setting == base_spec(best["accel"]),
            "bytes_per_triangle": r["bytes"] / triangles,
            "best": base_spec(best["accel"]) if best else "-", "best_speed": best["mrays_per_s"] if best else float("nan"),
            "best_peak": peaks.get((label, base_spec(best["accel"])), float("nan")) if best else float("nan"),
        })
    return rows


def megabytes(value):
    return "-" if value != value else f"{value / 1e6:.0f} MB"


def fmt_ratio(value):
    return "-" if value != value else f"{value:.2f}x" if value >= 0.01 else f"{value:.4f}x"


def stability_rows(docs):
    rows = []
    soup, sphere = docs.get("stability_soup"), docs.get("pareto_sphere_primary")
    if soup:
        strips = result(soup, "raystrips:width=8")
        auto = [r for r in soup["results"] if r.get("auto")]
        on_sphere = result(sphere, "raystrips:width=8") if sphere else None
        rows.append(("Ray-Strips on a soup (builtin:soup: the sphere's triangles, no shared vertex)",
                     f"raystrips:width=8 at {strips['bytes'] / soup['scene']['triangles']:.1f} B/tri and "
                     f"{fmt_ratio(ratio(soup, 'raystrips:width=8'))} robust Embree's speed"
                     + (f" (on the connected sphere: {on_sphere['bytes'] / sphere['scene']['triangles']:.1f} B/tri, "
                        f"{fmt_ratio(ratio(sphere, 'raystrips:width=8'))})" if on_sphere else "")
                     + f"; build: {strips['build_notes'].split(';')[0]}",
                     "; ".join(f"{short(base_spec(r['accel']))} chose {r['auto']['chosen']}" for r in auto)))
    stadium = docs.get("stability_stadium")
    if stadium:
        grid = result(stadium, "grid")
        grid_sphere = result(sphere, "grid") if sphere else None
        auto = [r for r in stadium["results"] if r.get("auto")]
        rows.append(("Hashed grid on a stadium (builtin:stadium: a small dense sphere in a huge box)",
                     f"grid at {fmt_ratio(ratio(stadium, 'grid'))} robust Embree's speed"
                     + (f" (on the lone sphere: {fmt_ratio(ratio(sphere, 'grid'))})" if grid_sphere else "")
                     + f"; {grid['build_notes'].split(';')[0]}",
                     "; ".join(f"{short(base_spec(r['accel']))} chose {r['auto']['chosen']}" for r in auto)))
        hmq = result(stadium, "hmq:width=8")
        rows.append(("HMQ, huge extents (builtin:stadium at 16 bits a side)",
                     f"hmq:width=8: vertices moved up to {hmq['vertex_error_max']:.3g} on a sphere of radius ~1 "
                     f"(box 1000 wide); hit agreement with robust Embree {100 * hmq['hit_agreement']:.3f}%, same "
                     f"primitive {100 * (hmq['prim_agreement'] or 0):.2f}%",
                     "auto sets HMQ's grid from the bound: a bound the 24-bit grid cannot reach rules HMQ out"))
    fur = docs.get("stability_fur_hmq")
    if fur:
        coarse, fine = result(fur, "hmq:width=8:bits=10"), result(fur, "hmq:width=8")
        auto = [r for r in fur["results"] if r.get("auto")]
        rows.append(("HMQ, thin features (builtin:fur: strands 0.004 wide)",
                     f"bits=10: same primitive {100 * (coarse['prim_agreement'] or 0):.2f}%, hit agreement "
                     f"{100 * coarse['hit_agreement']:.3f}%, vertices moved {coarse['vertex_error_max']:.3g}; bits=16: "
                     f"{100 * (fine['prim_agreement'] or 0):.2f}% / {100 * fine['hit_agreement']:.3f}%",
                     "; ".join(f"{short(base_spec(r['accel']))} chose {r['auto']['chosen']}" for r in auto)))
    proxy_fur, proxy_room = docs.get("stability_fur_proxy"), docs.get("stability_room_proxy")
    if proxy_fur:
        def hph_line(doc):
            none, hph = doc["results"][0], doc["results"][-1]
            overlap = re.search(r"hit overlap ([\d.]+)%", doc.get("proxy") or "")
            return (f"proxy hit overlap {overlap.group(1) if overlap else '?'}%, hph trace "
                    f"{hph['trace_mrays_per_s'] / none['trace_mrays_per_s']:.2f}x none's, approx_hit + zsort "
                    f"{100 * hph['overhead_share']:.0f}% of the time")
        rows.append(("The proxy on fur (builtin:fur: thin disconnected strands)",
                     hph_line(proxy_fur) + (f" (room: {hph_line(proxy_room)})" if proxy_room else ""),
                     "reorder.heuristic is the user's; fur's proxy is measured, not chosen"))
    leaks = docs.get("leaks")
    if leaks:
        rows.append(("Rays through shared edges (bench leak, builtin:sphere)",
                     ", ".join(f"{r['accel']}: {r['escaped']} of {r['rays']}" for r in leaks["results"]),
                     "auto takes robust Embree only"))
    return rows


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    out = Path(sys.argv[1])
    docs, runs = load(out)
    commands = {run["name"]: run for run in runs["runs"]}
    kinds = {stem: kind_of(doc) for stem, doc in docs.items()}
    peaks = render_peaks(docs, commands)

    def made_by(*stems):
        lines = [commands[s]["command"] + (f"   # {commands[s]['seconds']:.0f} s" if commands[s]["seconds"] else "")
                 for s in stems if s in commands]
        return "```sh\n" + "\n".join(lines) + "\n```\n" if lines else ""

    md = ["# wavetrace bench report", ""]
    md.append(f"{len(runs['runs'])} runs in {runs['total_seconds'] / 60:.1f} minutes"
              + (" (--quick: small scenes and counts; the figures are not the full matrix's)" if runs.get("quick") else "")
              + ". Speeds are medians of the runs on this machine; bytes are the structure's own accounting "
                "(with the mesh for a type that reads it in place). Every chart names the commands that made it.")
    md.append("")

    md += ["## Speed against bytes per triangle", "",
           "One point per accelerator setting; the blue step is the Pareto front (no setting has fewer bytes and more "
           "speed), red stars are `accel.type = auto`'s choices at the machine's budget and at tight ones.", ""]
    auto_table = []
    fronts = {}
    ordered = [run["name"] for run in runs["runs"] if run["name"] in docs]
    for stem in [s for s in ordered if kinds[s] == "accel" and commands[s]["section"] in ("pareto", "given")]:
        front = chart_pareto(stem, docs[stem], out)
        fronts[stem] = front
        md.append(f"![{stem}]({stem}.png)")
        md.append("")
        md.append(f"Pareto front: {', '.join(f'{short(f[2])} ({f[0]:.1f} B/tri, {f[1]:.2f} Mrays/s)' for f in front)}.")
        md.append("")
        md.append(made_by(stem))
        auto_table += auto_rows(stem, docs[stem], peaks)

    md += ["## accel.type = auto against the fastest that fits", "",
           "For each auto setting: what it chose (from estimates, before building), its estimate of the render's peak "
           "and the peak measured (VmHWM of a render of its own at the same image size: the footprint runs), against "
           "the fastest setting of the same run whose measured render peak fits the same budget and whose measured "
           f"hit-point error meets the same bound, leaving out leaky ones ({WATERTIGHT_NOTE}). Auto's estimates are "
           "conservative (the largest bytes per triangle measured on docs/memory.md's scenes), so it may take a smaller, "
           "slower setting than the fastest that fits; it ranks the ones that fit by their median speed on these "
           "scenes, divided for chunked ones by a slowdown that grows with the chunk boxes around a triangle.", "",
           "| run | auto | budget | bound | chose | estimate | peak | Mrays/s | fastest that fits | its peak | its Mrays/s "
           "| auto / fastest |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in auto_table:
        row["ratio"] = row["speed"] / row["best_speed"] if row["best_speed"] > 0 else float("nan")
        md.append(f"| {row['scene']} {row['rays']} | {row['auto']} | {row['budget'] / 1e6:.0f} MB | {row['bound']:.3g} | "
                  f"{row['chosen']} | {megabytes(row['estimate'])} | {megabytes(row['peak'])}"
                  f"{' **over the budget**' if row['fits'] is False else ''} | {row['speed']:.2f} | "
                  f"{row['best']} | {megabytes(row['best_peak'])} | {row['best_speed']:.2f} | "
                  f"{fmt_ratio(row['ratio'])}{' (same setting)' if row['same_setting'] else ''} |")
    if auto_table:
        within = [row for row in auto_table if row["same_setting"] or row["ratio"] >= 0.9]
        measured = [row for row in auto_table if row["fits"] is not None]
        md += ["", f"Auto is within 10% of the fastest that fits, or took that very setting (whose two runs differ "
                   f"by the machine's noise alone), on {len(within)} of {len(auto_table)} runs; its render's measured "
                   f"peak fits its budget on {sum(row['fits'] for row in measured)} of {len(measured)}."]
    md.append("")
    footprint_stems = [s for s in ordered if commands[s].get("section") == "footprint"]
    if footprint_stems:
        labels = list(dict.fromkeys(label for (label, _) in peaks))
        settings = list(dict.fromkeys(re.sub(r":budget=\d+MB", ":budget", short(spec)) for (_, spec) in peaks))
        by_setting = {(label, re.sub(r":budget=\d+MB", ":budget", short(spec))): peak for (label, spec), peak in peaks.items()}
        md += ["Render peaks (VmHWM, MB) of every setting; `chunked`: in chunks of an eighth of the scene, `budget`: "
               "the tight budgets above.", "",
               "| setting | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
        for setting in settings:
            md.append(f"| {setting} | " + " | ".join(
                f"{by_setting[(label, setting)] / 1e6:.0f}" if (label, setting) in by_setting else "-"
                for label in labels) + " |")
        md += ["", made_by(*footprint_stems)]
        estimates = estimate_rows(docs, commands, peaks)
        if estimates:
            under = [key for key, (estimate, peak) in estimates.items() if estimate < peak]
            md += ["Auto's estimate of each candidate's render peak (from its pass, before building; HMQ's at "
                   "the run's bound) against the peak measured for that setting above: "
                   f"{len(estimates) - len(under)} of {len(estimates)} estimates lie at or above the measured peak"
                   + (f"; under it: {', '.join(f'{setting} on {label}' for label, setting in under)}." if under else "."),
                   "", "| scene | setting | estimate | measured peak | estimate / peak |", "|---|---|---|---|---|"]
            for (label, setting), (estimate, peak) in estimates.items():
                md.append(f"| {label} | {short(setting)} | {megabytes(estimate)} | {megabytes(peak)} | "
                          f"{estimate / peak:.2f} |")
            md.append("")

    error_stems = [s for s in docs if kinds[s] == "accel" and s.startswith("hmq_error")]
    image_stems = [s for s in docs if kinds[s] == "image"]
    md += ["## HMQ: error against speed", ""]
    for stem in error_stems:
        chart_hmq_error(stem, docs[stem], out)
        md += [f"![{stem}]({stem}.png)", "", made_by(stem)]
    for stem in image_stems:
        chart_image(stem, docs[stem], out)
        doc = docs[stem]
        noise = next((r for r in doc["results"] if r.get("noise_floor")), None)
        pixel = next((r for r in doc["results"] if "epsilon=pixel" in r["accel"]), None)
        md += [f"![{stem}]({stem}.png)", ""]
        if noise and pixel:
            md += [f"At `epsilon = pixel` ({short(pixel['accel'])}) the image RMSE against {doc['reference']} is "
                   f"{pixel['rmse']:.3g}; the same renderer against itself with the next seed (Monte Carlo noise) gives "
                   f"{noise['rmse']:.3g}: the pixel bound's error is "
                   f"{'within' if pixel['rmse'] <= noise['rmse'] else 'ABOVE'} the noise "
                   f"({pixel['rmse'] / noise['rmse']:.2f}x).", ""]
        md.append(made_by(stem))

    fault_docs = [docs[s] for s in docs if kinds[s] == "reorder" and s.startswith("faults")]
    if fault_docs:
        series = chart_faults("faults", fault_docs, out)
        md += ["## Page faults against budget per reorder heuristic", "", "![faults](faults.png)", "",
               "Solid: the simulated pager (bvh's every read, one thread); dashed: real paging of a world file "
               "(`memory.backing = file`, pages read with O_DIRECT into a pool of the budget).", "",
               "| heuristic | " + " | ".join(f"{b}% {k}" for b, k in sorted({(v[0], k) for (h, k), vs in series.items() for v in vs}, key=lambda x: (x[1], -x[0]))) + " |"]
        columns = sorted({(v[0], k) for (h, k), vs in series.items() for v in vs}, key=lambda x: (x[1], -x[0]))
        md.append("|---" * (len(columns) + 1) + "|")
        for heuristic in dict.fromkeys(h for h, k in series):
            cells = []
            for budget, kind in columns:
                value = dict(series.get((heuristic, kind), [])).get(budget)
                cells.append("-" if value is None else str(value))
            md.append(f"| {heuristic} | " + " | ".join(cells) + " |")
        md += ["", made_by("world_room", *[s for s in docs if s.startswith("faults")])]

    stage_docs = {s: docs[s] for s in docs if kinds[s] == "render" and s.startswith("stages")}
    if stage_docs:
        chart_stages("stages", stage_docs, out)
        md += ["## Where a render's time goes", "", "![stages](stages.png)", ""]
        for stem, doc in stage_docs.items():
            total = sum(stage["seconds"] for stage in doc["stages"]) or 1.0
            md.append(f"- {stem}: " + ", ".join(f"{stage['name']} {100 * stage['seconds'] / total:.1f}%"
                                                for stage in doc["stages"]))
        md += ["", made_by(*stage_docs)]

    rows = stability_rows(docs)
    md += ["## Stability: each method on its known failure case", "",
           "| method on its failure case | measured | accel.type = auto |", "|---|---|---|"]
    for method, measured, chosen in rows:
        md.append(f"| {method} | {measured} | {chosen} |")
    md += ["", made_by(*[s for s in docs if s.startswith("stability") or s == "leaks"])]

    (out / "report.md").write_text("\n".join(md) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
