#!/usr/bin/python3
"""What a page pool's replacement policy could buy on a recorded render.

Reads a page trace (memory.page_trace: little-endian uint32 page numbers, one per touch) and
replays it through a pool of N slots under LRU, which the real pager approximates, under a
segmented LRU (a scan-resistant policy: new pages enter a probation part, a page touched again
there moves to the protected rest), under ARC (adaptive between recency and frequency), under
LRU told the next W touches (--window), and under Belady's optimum (evict the page used furthest
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


def arc_faults(trace, slots):
    """Adaptive replacement (Megiddo and Modha 2003): pages seen once (T1) and more (T2), with
    ghost lists of what each lost (B1, B2) steering how much of the pool the first may hold.
    Touches of one page in a row count once: a walk's steps within a page are one use of it,
    not the second use that would make it frequent."""
    if trace.size > 1:
        trace = trace[np.concatenate(([True], trace[1:] != trace[:-1]))]
    target = 0  # the share of the pool T1 aims for
    t1, t2 = collections.OrderedDict(), collections.OrderedDict()
    b1, b2 = collections.OrderedDict(), collections.OrderedDict()
    faults = 0

    def replace(page_in_b2):
        if t1 and (len(t1) > target or (page_in_b2 and len(t1) == target)):
            b1[t1.popitem(last=False)[0]] = True
        else:
            b2[t2.popitem(last=False)[0]] = True

    for page in trace.tolist():
        if page in t1:
            del t1[page]
            t2[page] = True
            continue
        if page in t2:
            t2.move_to_end(page)
            continue
        faults += 1
        if page in b1:
            target = min(slots, target + max(len(b2) // len(b1), 1))
            replace(False)
            del b1[page]
            t2[page] = True
            continue
        if page in b2:
            target = max(0, target - max(len(b1) // len(b2), 1))
            replace(True)
            del b2[page]
            t2[page] = True
            continue
        if len(t1) + len(b1) == slots:
            if len(t1) < slots:
                b1.popitem(last=False)
                replace(False)
            else:
                t1.popitem(last=False)
        elif len(t1) + len(t2) + len(b1) + len(b2) >= slots:
            if len(t1) + len(t2) + len(b1) + len(b2) == 2 * slots:
                b2.popitem(last=False)
            replace(False)
        t1[page] = True
    return faults


def windowed_future_faults(trace, slots, window):
    """LRU that knows the next `window` touches: it evicts the least recently used page that
    none of them touches (plain LRU when each resident page is touched there). What a pool told
    the pages of the rays just ahead (a look-ahead that marks, say) could buy; `window` 0 is LRU."""
    following = next_uses(trace).tolist()
    pool = collections.OrderedDict()  # page -> its next use, least recently used first
    faults = 0
    for i, page in enumerate(trace.tolist()):
        if page in pool:
            pool.move_to_end(page)
            pool[page] = following[i]
            continue
        faults += 1
        if len(pool) == slots:
            victim = next((p for p, use in pool.items() if use > i + window), None)
            del pool[next(iter(pool)) if victim is None else victim]
        pool[page] = following[i]
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
    parser.add_argument("--window", type=int, action="append", default=[],
                        help="also LRU knowing the next WINDOW touches (repeatable; slow: pool-sized scans)")
    args = parser.parse_args()
    trace = np.fromfile(args.trace, dtype="<u4")
    if trace.size == 0:
        sys.exit(f"{args.trace}: no touches recorded")
    print(f"{args.trace}: {trace.size} touches of {np.unique(trace).size} distinct pages")
    if not 0.0 < args.probation <= 1.0:
        sys.exit(f"--probation {args.probation}: a share of the pool, in (0, 1]")
    if any(window < 0 for window in args.window):
        sys.exit("--window: a count of touches, 0 or more")
    print(f"slots      LRU  segmented LRU ({args.probation:g} probation)      ARC  optimal  LRU/optimal" +
          "".join(f"  LRU, next {window}" for window in args.window))
    for slots in args.slots:
        if slots < 1:
            sys.exit(f"--slots {slots}: a pool holds at least one page")
        lru, best = lru_faults(trace, slots), optimal_faults(trace, slots)
        segmented = segmented_lru_faults(trace, slots, args.probation)
        line = f"{slots:5d} {lru:8d} {segmented:30d} {arc_faults(trace, slots):8d} {best:8d} {lru / best:12.2f}"
        for window in args.window:
            line += f" {windowed_future_faults(trace, slots, window):{len(f'  LRU, next {window}')}d}"
        print(line)


if __name__ == "__main__":
    main()
