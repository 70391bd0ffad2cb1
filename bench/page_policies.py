#!/usr/bin/python3
"""What a page pool's replacement policy could buy on a recorded render.

Reads a page trace (memory.page_trace: little-endian uint32 page numbers, one per touch) and
replays it through a pool of N slots under LRU, which the real pager approximates, under a
segmented LRU (a scan-resistant policy: new pages enter a probation part, a page touched again
there moves to the protected rest), and under Belady's optimum (evict the page used furthest
in the future), which no policy can beat. The gap between LRU and the optimum bounds what a
smarter pool can save; the rest is the order of the rays.

    build/wavetrace bench reorder --scene W.wtw ... --heuristics hph_origin \\
        --set memory.backing=file --set memory.budget=24% --set memory.page_trace=out/hph_origin.pages
    /usr/bin/python3 bench/page_policies.py out/hph_origin.pages --slots 290

(--slots: the pool's pages, memory.budget over memory.page_bytes, as the render's header says.)
About 2 s per million touches.
"""
import argparse
import collections
import heapq
import sys

import numpy as np


def lru_faults(trace, slots):
    pool = collections.OrderedDict()
    faults = 0
    for page in trace.tolist():
        if page in pool:
            pool.move_to_end(page)
            continue
        faults += 1
        if len(pool) == slots:
            pool.popitem(last=False)
        pool[page] = True
    return faults


def segmented_lru_faults(trace, slots, probation_share):
    protected_slots = max(0, min(slots - 1, int(slots * (1.0 - probation_share))))
    probation, protected = collections.OrderedDict(), collections.OrderedDict()
    faults = 0
    for page in trace.tolist():
        if page in protected:
            protected.move_to_end(page)
            continue
        if page in probation:
            del probation[page]
            protected[page] = True
            if len(protected) > protected_slots:  # the protected part's oldest goes back on probation
                demoted, _ = protected.popitem(last=False)
                probation[demoted] = True
            continue
        faults += 1
        if len(probation) + len(protected) == slots:
            (probation if probation else protected).popitem(last=False)
        probation[page] = True
    return faults


def next_uses(trace):
    """For each touch, the index of the next touch of the same page (len(trace): never)."""
    order = np.argsort(trace, kind="stable")
    following = np.full(len(trace), len(trace), dtype=np.int64)
    same = trace[order[1:]] == trace[order[:-1]]
    following[order[:-1][same]] = order[1:][same]
    return following


def optimal_faults(trace, slots):
    following = next_uses(trace).tolist()
    resident = {}  # page -> its next use
    heap = []  # (-next use, page), stale entries skipped on pop
    faults = 0
    for i, page in enumerate(trace.tolist()):
        if page not in resident:
            faults += 1
            if len(resident) == slots:
                while True:
                    negative_use, victim = heapq.heappop(heap)
                    if resident.get(victim) == -negative_use:
                        del resident[victim]
                        break
        resident[page] = following[i]
        heapq.heappush(heap, (-following[i], page))
    return faults


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trace", help="a page trace written by memory.page_trace")
    parser.add_argument("--slots", type=int, action="append", required=True, help="pool size in pages (repeatable)")
    parser.add_argument("--probation", type=float, default=0.25,
                        help="the segmented LRU's probation part, a share of the pool (default 0.25)")
    args = parser.parse_args()
    trace = np.fromfile(args.trace, dtype="<u4")
    if trace.size == 0:
        sys.exit(f"{args.trace}: no touches recorded")
    print(f"{args.trace}: {trace.size} touches of {np.unique(trace).size} distinct pages")
    if not 0.0 < args.probation <= 1.0:
        sys.exit(f"--probation {args.probation}: a share of the pool, in (0, 1]")
    print(f"slots      LRU  segmented LRU ({args.probation:g} probation)  optimal  LRU/optimal")
    for slots in args.slots:
        if slots < 1:
            sys.exit(f"--slots {slots}: a pool holds at least one page")
        lru, best = lru_faults(trace, slots), optimal_faults(trace, slots)
        segmented = segmented_lru_faults(trace, slots, args.probation)
        print(f"{slots:5d} {lru:8d} {segmented:30d} {best:8d} {lru / best:12.2f}")


if __name__ == "__main__":
    main()
