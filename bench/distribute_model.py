#!/usr/bin/env python3
"""Image mode past this machine, on paper (issue 34, item 5): from one measured distributed
render's stats JSON (wavetrace render --stats under mpirun), the rays/s of N ranks of one
thread each over a network of B Gb/s.

The model, per rank: its share of the work at the measured speed of one rank, plus waiting for
ranges (the measured wait a range on this machine, plus one network round trip), plus half a
range of imbalance at the end, plus the film sum (a binomial-tree reduce: log2 N steps of the
whole film over the link). It assumes the ranks run at the speed of one measured rank (the
world in memory on every node, as image mode needs), and leaves out the load of the world.
Usage: bench/distribute_model.py STATS.json [--ranks 16,64,256] [--gbps 10,100] [--rtt-us 20]"""
import argparse
import json
import math


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("stats")
    parser.add_argument("--ranks", default="16,64,256")
    parser.add_argument("--gbps", default="10,100")
    parser.add_argument("--rtt-us", type=float, default=20.0, help="network round trip in microseconds")
    args = parser.parse_args()
    stats = json.load(open(args.stats))
    d = stats["distribute"]
    rays = d["rays_traced"]
    per_rank = d["per_rank"]
    # One rank's speed: rays it traced over its render time, the mean over ranks.
    rank_rate = sum(r["rays_traced"] / r["render_seconds"] for r in per_rank) / len(per_rank)
    ranges = sum(r["ranges"] for r in per_rank)
    wait_per_range = sum(r["wait_seconds"] for r in per_rank if r["rank"] != 0) / max(
        1, sum(r["ranges"] for r in per_rank if r["rank"] != 0))
    film_bytes = stats["image"]["width"] * stats["image"]["height"] * 3 * 8
    print(f"measured: {len(per_rank)} ranks, {rays:,} rays, one rank {rank_rate * 1e-6:.3f} Mrays/s, "
          f"{ranges} ranges, {wait_per_range * 1e3:.3f} ms waited a range, film {film_bytes / 1e6:.2f} MB, "
          f"{(ranges * 16 + film_bytes * (len(per_rank) - 1)) / rays:.3f} bytes sent a ray")
    print("| ranks | Gb/s | work s | range waits s | imbalance s | film sum s | render s | Mrays/s | efficiency |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for n in [int(x) for x in args.ranks.split(",")]:
        for gbps in [float(x) for x in args.gbps.split(",")]:
            work = rays / (n * rank_rate)
            ranges_each = 64  # distribute.range_rays = 0 deals 64 ranges a rank
            waits = ranges_each * (wait_per_range + args.rtt_us * 1e-6)
            imbalance = 0.5 * work / ranges_each
            film = math.log2(n) * film_bytes / (gbps * 1e9 / 8)
            total = work + waits + imbalance + film
            print(f"| {n} | {gbps:g} | {work:.3f} | {waits:.3f} | {imbalance:.3f} | {film:.3f} | {total:.3f} | "
                  f"{rays / total * 1e-6:.2f} | {work / total:.0%} |")


if __name__ == "__main__":
    main()
