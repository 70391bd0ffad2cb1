#!/usr/bin/env python3
"""Checks of bench/report.py's charts that a reader relies on (run by ctest as ReportCharts,
with Debian's python3 and its matplotlib): the Pareto chart's bytes-per-triangle axis is
labelled with the values a reader looks for, and its legend covers no point; a bench JSON
named any way charts with --from."""
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402


def accel_doc(points):
    return {"scene": {"source": "builtin:room:200k", "triangles": 1000}, "rays": {"kind": "primary"}, "threads": 2,
            "results": [{"accel": label, "bytes": bpt * 1000, "mrays_per_s": speed} for label, bpt, speed in points]}


class ParetoChart(unittest.TestCase):
    def chart(self, doc):
        figures = []
        close = report.plt.close
        report.plt.close = figures.append  # keep the figure to look at
        try:
            with tempfile.TemporaryDirectory() as out:
                report.chart_pareto("pareto_test", doc, Path(out))
        finally:
            report.plt.close = close
        figure = next(f for f in figures if hasattr(f, "canvas"))
        figure.canvas.draw()
        return figure, figure.axes[0]

    def test_bytes_axis_names_round_values(self):
        doc = accel_doc([("hmq:width=8", 9.4, 2.9), ("mlgrid", 47.6, 1.0), ("embree:mode=robust", 83.5, 5.6),
                         ("bvh:width=8", 74.0, 3.5), ("raystrips:width=8", 14.0, 1.9), ("arraygrid", 4.2, 0.5)])
        _, axes = self.chart(doc)
        labels = [t.get_text() for t in axes.get_xticklabels() if t.get_text()]
        self.assertEqual(labels, ["5", "10", "20", "50"])
        self.assertEqual([t.get_text() for t in axes.get_xticklabels(minor=True) if t.get_text()], [])

    def test_legend_hides_no_point(self):
        # The points of room:200k whose mlgrid the legend once hid, at the lower right.
        doc = accel_doc([("hmq:width=8", 9.4, 2.9), ("mlgrid", 47.6, 0.2), ("embree:mode=robust", 83.5, 5.6),
                         ("auto:memory_budget=1 (mlgrid)", 47.6, 0.21)])
        figure, axes = self.chart(doc)
        legend = axes.get_legend().get_window_extent(figure.canvas.get_renderer())
        for collection in axes.collections:
            for x, y in collection.get_offsets():
                px, py = axes.transData.transform((x, y))
                self.assertFalse(legend.contains(px, py), f"the legend covers the point at ({x}, {y})")


class FileNames(unittest.TestCase):
    def test_any_name_is_its_own_scene_label(self):
        self.assertEqual(report.scene_label("pareto_room_primary"), "room")
        self.assertEqual(report.scene_label("a"), "a")


if __name__ == "__main__":
    unittest.main()
