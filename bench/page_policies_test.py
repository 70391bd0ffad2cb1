#!/usr/bin/python3
"""Checks of bench/page_policies.py (run by ctest as PagePolicies): LRU and Belady's optimum
against hand-counted sequences and against a plain replay that looks ahead by brute force."""
import random
import sys
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import page_policies  # noqa: E402


def brute_force_optimal(trace, slots):
    resident, faults = set(), 0
    for i, page in enumerate(trace):
        if page in resident:
            continue
        faults += 1
        if len(resident) == slots:
            def next_use(p):
                later = [j for j in range(i + 1, len(trace)) if trace[j] == p]
                return later[0] if later else len(trace)
            resident.remove(max(sorted(resident), key=next_use))
        resident.add(page)
    return faults


class Policies(unittest.TestCase):
    def test_hand_counted(self):
        trace = np.array([1, 2, 3, 1, 4, 1, 2, 3], dtype=np.uint32)
        self.assertEqual(page_policies.lru_faults(trace, 2), 7)
        self.assertEqual(page_policies.optimal_faults(trace, 2), 6)
        self.assertEqual(page_policies.lru_faults(trace, 3), 6)
        self.assertEqual(page_policies.optimal_faults(trace, 3), 5)

    def test_segmented_lru_keeps_a_page_touched_twice_through_a_scan(self):
        # Page 1 is touched twice, then pages 2..5 are scanned once: LRU evicts page 1 and
        # faults on its return; the segmented pool keeps it in its protected part.
        trace = np.array([1, 1, 2, 3, 4, 5, 1], dtype=np.uint32)
        self.assertEqual(page_policies.lru_faults(trace, 3), 6)
        self.assertEqual(page_policies.segmented_lru_faults(trace, 3, 0.5), 5)
        # With the whole pool on probation it is LRU.
        generator = random.Random(3)
        for _ in range(10):
            trace = np.array([generator.randrange(9) for _ in range(100)], dtype=np.uint32)
            self.assertEqual(page_policies.segmented_lru_faults(trace, 4, 1.0), page_policies.lru_faults(trace, 4))

    def test_arc_keeps_a_page_touched_twice_through_a_scan(self):
        trace = np.array([1, 2, 1, 3, 4, 5, 1], dtype=np.uint32)
        self.assertEqual(page_policies.lru_faults(trace, 3), 6)
        self.assertEqual(page_policies.arc_faults(trace, 3), 5)
        # Touches in a row are one use: page 1 touched twice in a row is not kept through the scan.
        self.assertEqual(page_policies.arc_faults(np.array([1, 1, 2, 3, 4, 5, 1], dtype=np.uint32), 3), 6)
        # Never more faults than distinct pages, nor fewer than the optimum.
        generator = random.Random(7)
        for _ in range(20):
            trace = np.array([generator.randrange(15) for _ in range(300)], dtype=np.uint32)
            slots = generator.randrange(1, 12)
            arc = page_policies.arc_faults(trace, slots)
            self.assertGreaterEqual(arc, page_policies.optimal_faults(trace, slots))
            self.assertGreaterEqual(arc, np.unique(trace).size)

    def test_knowing_the_next_touches(self):
        # Hand-counted: told one touch ahead, the pool keeps page 1 (touched next) at touch 2 and
        # evicts 2 instead; 6 faults, the optimum's, against LRU's 7.
        trace = np.array([1, 2, 3, 1, 4, 1, 2, 3], dtype=np.uint32)
        self.assertEqual(page_policies.windowed_future_faults(trace, 2, 1), 6)
        generator = random.Random(11)
        for _ in range(20):
            trace = np.array([generator.randrange(12) for _ in range(200)], dtype=np.uint32)
            slots = generator.randrange(1, 10)
            # Told nothing, it is LRU.
            self.assertEqual(page_policies.windowed_future_faults(trace, slots, 0), page_policies.lru_faults(trace, slots))
            self.assertGreaterEqual(page_policies.windowed_future_faults(trace, slots, 5),
                                    page_policies.optimal_faults(trace, slots))

    def test_optimal_is_beladys_and_never_worse_than_lru(self):
        generator = random.Random(5)
        for _ in range(30):
            trace = [generator.randrange(12) for _ in range(200)]
            slots = generator.randrange(1, 10)
            array = np.array(trace, dtype=np.uint32)
            best = page_policies.optimal_faults(array, slots)
            self.assertEqual(best, brute_force_optimal(trace, slots))
            self.assertLessEqual(best, page_policies.lru_faults(array, slots))


if __name__ == "__main__":
    unittest.main()
