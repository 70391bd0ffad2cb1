// The runs of grid cells a triangle overlaps: every cell holding a point of the triangle is
// listed (checked by sampling), every cell listed comes within the slack of the triangle
// (checked by a separating axis test), never outside the bounding box's cells, and a strand
// lying across the grid takes about n cells where its bounding box takes n^3.
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <tuple>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "wavetrace/accel/grid/cell_runs_in_lanes.hpp"
#include "wavetrace/kernels/triangle_cell_runs.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"

namespace wavetrace {
namespace {

using Cell = std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>;  // (z, y, x)

const CellGridFrame kFrame{glm::dvec3(-1.0, -2.0, 0.5), glm::dvec3(0.25, 0.5, 0.125), glm::dvec3(0.25, 0.5, 0.125) * 1e-3};
const glm::uvec3 kCells(16, 8, 32);

glm::uvec3 cell_of(const glm::dvec3& point, const glm::dvec3& grow) {
  const glm::dvec3 at = glm::floor((point + grow - kFrame.lower) / kFrame.cell_size);
  return glm::uvec3(glm::clamp(at, glm::dvec3(0.0), glm::dvec3(kCells) - 1.0));
}

struct Runs {
  std::set<Cell> cells;
  glm::uvec3 box_lower, box_upper;
};

Runs runs_of(const std::array<glm::vec3, 3>& t) {
  Runs runs;
  const glm::dvec3 least = glm::min(glm::dvec3(t[0]), glm::min(glm::dvec3(t[1]), glm::dvec3(t[2])));
  const glm::dvec3 most = glm::max(glm::dvec3(t[0]), glm::max(glm::dvec3(t[1]), glm::dvec3(t[2])));
  runs.box_lower = cell_of(least, -kFrame.slack);
  runs.box_upper = cell_of(most, kFrame.slack);
  for_each_triangle_cell_run(t[0], t[1], t[2], kFrame, runs.box_lower, runs.box_upper, 0, kCells.z - 1,
                             [&](std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
                               EXPECT_LE(x_first, x_last);
                               for (std::uint32_t x = x_first; x <= x_last; ++x) {
                                 EXPECT_TRUE(runs.cells.emplace(z, y, x).second) << "cell listed twice";
                               }
                             });
  return runs;
}

// Separating axis test of a triangle against a box (the box's 3 axes, the triangle's normal,
// the 9 edge cross products), in double with a margin: true when they may touch.
bool may_touch(const std::array<glm::vec3, 3>& t, const glm::dvec3& lower, const glm::dvec3& upper) {
  const glm::dvec3 center = (lower + upper) * 0.5, half = (upper - lower) * 0.5;
  const glm::dvec3 v[3] = {glm::dvec3(t[0]) - center, glm::dvec3(t[1]) - center, glm::dvec3(t[2]) - center};
  const glm::dvec3 edges[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  std::vector<glm::dvec3> axes = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, glm::cross(edges[0], edges[1])};
  for (const glm::dvec3& e : edges) {
    for (int a = 0; a < 3; ++a) {
      glm::dvec3 unit(0.0);
      unit[a] = 1.0;
      axes.push_back(glm::cross(unit, e));
    }
  }
  for (const glm::dvec3& axis : axes) {
    const double length = glm::length(axis);
    if (length < 1e-12) continue;
    const double p0 = glm::dot(v[0], axis), p1 = glm::dot(v[1], axis), p2 = glm::dot(v[2], axis);
    const double radius = glm::dot(half, glm::abs(axis));
    const double margin = 1e-9 * length;
    if (std::min({p0, p1, p2}) > radius + margin || std::max({p0, p1, p2}) < -radius - margin) return false;
  }
  return true;
}

void expect_exact_runs(const std::array<glm::vec3, 3>& t, std::mt19937& random) {
  const Runs runs = runs_of(t);
  for (const auto& [z, y, x] : runs.cells) {
    ASSERT_TRUE(glm::all(glm::greaterThanEqual(glm::uvec3(x, y, z), runs.box_lower)) &&
                glm::all(glm::lessThanEqual(glm::uvec3(x, y, z), runs.box_upper)))
        << "a cell outside the bounding box's";
    const glm::dvec3 lower = kFrame.lower + glm::dvec3(x, y, z) * kFrame.cell_size - kFrame.slack;
    const glm::dvec3 upper = lower + kFrame.cell_size + 2.0 * kFrame.slack;
    EXPECT_TRUE(may_touch(t, lower, upper)) << "cell (" << x << ", " << y << ", " << z << ") does not meet the triangle";
  }
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int sample = 0; sample < 4000; ++sample) {
    double a = unit(random), b = unit(random);
    if (sample % 4 == 0) b = 0.0;  // on an edge, where cells are easiest to lose
    if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
    const glm::dvec3 point = glm::dvec3(t[0]) + a * glm::dvec3(t[1] - t[0]) + b * glm::dvec3(t[2] - t[0]);
    const glm::uvec3 cell = cell_of(point, glm::dvec3(0.0));
    ASSERT_TRUE(runs.cells.contains({cell.z, cell.y, cell.x}))
        << "point (" << point.x << ", " << point.y << ", " << point.z << ") lies in a cell not listed";
  }
}

TEST(TriangleCellRuns, ListEveryCellTheTriangleMeetsAndNoOther) {
  std::mt19937 random(7);
  const glm::dvec3 extent = glm::dvec3(kCells) * kFrame.cell_size;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto point_in_grid = [&] {
    return glm::vec3(kFrame.lower + glm::dvec3(unit(random), unit(random), unit(random)) * extent);
  };
  for (int triangle = 0; triangle < 300; ++triangle) {
    const glm::vec3 a = point_in_grid();
    std::array<glm::vec3, 3> t;
    switch (triangle % 5) {
      case 0: t = {a, point_in_grid(), point_in_grid()}; break;  // large, any direction
      case 1: {  // a strand: long and thin
        const glm::vec3 b = point_in_grid();
        t = {a, b, b + glm::vec3(0.01f, 0.0f, 0.005f)};
        break;
      }
      case 2: t = {a, a + glm::vec3(0.3f, 0.0f, 0.0f), a + glm::vec3(0.0f, 0.0f, 0.4f)}; break;  // level: one y
      case 3: t = {a, a + glm::vec3(0.0f, 1.5f, 0.0f), a + glm::vec3(0.0f, 0.0f, 2.0f)}; break;  // in an x plane
      default: t = {a, a + glm::vec3(0.1f, 0.2f, 0.05f), a + glm::vec3(-0.05f, 0.1f, 0.2f)}; break;  // small
    }
    // A grid spans its mesh: corners outside it would be given to its border cells.
    for (glm::vec3& corner : t) corner = glm::clamp(corner, glm::vec3(kFrame.lower), glm::vec3(kFrame.lower + extent));
    expect_exact_runs(t, random);
  }
  // Degenerate: a segment and a point give the cells they meet.
  const glm::vec3 a(-0.9f, -1.7f, 0.6f), b(2.9f, 1.9f, 4.4f);
  expect_exact_runs({a, b, a}, random);
  expect_exact_runs({a, a, a}, random);
  EXPECT_EQ(runs_of({a, a, a}).cells.size(), 1u);
}

TEST(TriangleCellRuns, AStrandAcrossTheGridTakesALineOfCellsNotItsBox) {
  const glm::vec3 from(-0.93f, -1.9f, 0.58f), to(2.9f, 1.8f, 4.3f);  // corner to corner
  const Runs runs = runs_of({from, to, to + glm::vec3(0.001f, 0.0f, 0.0f)});
  const glm::uvec3 box = runs.box_upper - runs.box_lower + 1u;
  EXPECT_GT(std::size_t(box.x) * box.y * box.z, 50 * runs.cells.size());  // nearly the whole grid
  std::size_t touched = 0;  // every cell of the grid that meets it
  for (std::uint32_t z = 0; z < kCells.z; ++z)
    for (std::uint32_t y = 0; y < kCells.y; ++y)
      for (std::uint32_t x = 0; x < kCells.x; ++x) {
        const glm::dvec3 lower = kFrame.lower + glm::dvec3(x, y, z) * kFrame.cell_size - kFrame.slack;
        touched += may_touch({from, to, to + glm::vec3(0.001f, 0.0f, 0.0f)}, lower, lower + kFrame.cell_size + 2.0 * kFrame.slack);
      }
  EXPECT_EQ(runs.cells.size(), touched);
  // A line crosses at most one cell per face it passes: fewer than the sum of the cells per axis.
  EXPECT_LE(runs.cells.size(), std::size_t(kCells.x + kCells.y + kCells.z) + 3);
  EXPECT_GE(runs.cells.size(), std::size_t(kCells.z));
}

TEST(TriangleCellRuns, LayersOutsideTheCallersRangeAreLeftToTheirOwnCalls) {
  const std::array<glm::vec3, 3> t = {glm::vec3(-0.9f, -1.9f, 0.6f), glm::vec3(2.5f, 1.0f, 4.0f), glm::vec3(0.0f, 1.5f, 2.0f)};
  const Runs whole = runs_of(t);
  std::set<Cell> pieced;
  for (std::uint32_t first = 0; first < kCells.z; first += 5) {
    for_each_triangle_cell_run(t[0], t[1], t[2], kFrame, whole.box_lower, whole.box_upper, first, first + 4,
                               [&](std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
                                 EXPECT_GE(z, first);
                                 EXPECT_LE(z, first + 4);
                                 for (std::uint32_t x = x_first; x <= x_last; ++x) pieced.emplace(z, y, x);
                               });
  }
  EXPECT_EQ(pieced, whole.cells);
}

// The grids' eight lanes must give each triangle the scalar function's runs in its order, so
// that a grid built either way is the same to the byte: triangles of every shape, in slabs of
// one to three layers, a few at a time and eight.
TEST(TriangleCellRuns, EightLanesGiveTheScalarRunsInTheirOrder) {
#if WAVETRACE_AVX512_DISPATCH || WAVETRACE_AVX512F
  bool runs_avx512 = false;
  for (const KernelIsa isa : runnable_kernel_isas()) runs_avx512 |= cell_runs_in_lanes(isa);
  if (!runs_avx512) GTEST_SKIP() << "this CPU has no AVX-512: the grids find their runs one triangle at a time";
  std::mt19937 random(11);
  const glm::dvec3 extent = glm::dvec3(kCells) * kFrame.cell_size;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto point_in_grid = [&] {
    return glm::vec3(kFrame.lower + glm::dvec3(unit(random), unit(random), unit(random)) * extent);
  };
  const auto offset = [&](double cells) {
    return glm::vec3(glm::dvec3(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5) * kFrame.cell_size * cells);
  };
  std::vector<TriangleCellVisit> visits;
  for (int triangle = 0; visits.size() < 6000; ++triangle) {
    const glm::vec3 a = point_in_grid();
    std::array<glm::vec3, 3> t;
    switch (triangle % 7) {
      case 0: t = {a, a + offset(6.0), a + offset(6.0)}; break;  // a few cells on every axis
      case 1: {  // a strand: long and thin
        const glm::vec3 along = offset(10.0);
        t = {a, a + along, a + along + glm::vec3(0.002f, 0.0f, 0.001f)};
        break;
      }
      case 2: t = {a, a + glm::vec3(0.0f, 0.6f, 0.1f), a + glm::vec3(0.0f, 0.1f, 0.4f)}; break;  // in an x plane
      case 3: t = {a, a + glm::vec3(0.5f, 0.0f, 0.1f), a + glm::vec3(0.1f, 0.0f, 0.4f)}; break;  // in a y plane
      case 4: t = {a, a + offset(3.0), a}; break;  // a segment
      case 5: t = {a, a + offset(2.0), a + offset(2.0)}; break;  // small
      default: t = {a, a + offset(14.0), a + offset(14.0)}; break;  // some wider than a list's rows
    }
    for (glm::vec3& corner : t) corner = glm::clamp(corner, glm::vec3(kFrame.lower), glm::vec3(kFrame.lower + extent));
    const Runs whole = runs_of(t);
    const std::uint32_t layers = 1 + std::uint32_t(triangle % 3);
    for (std::uint32_t first = whole.box_lower.z / layers * layers; first <= whole.box_upper.z; first += layers) {
      visits.push_back({t[0], t[1], t[2], whole.box_lower, whole.box_upper, first, first + layers - 1});
    }
  }
  std::vector<const TriangleCellVisit*> taken;
  for (const TriangleCellVisit& visit : visits) {
    if (fits_cell_run_lanes(visit)) taken.push_back(&visit);
  }
  EXPECT_GT(taken.size(), visits.size() / 3);  // the lanes take most kinds of triangle
  std::size_t compared = 0;
  for (std::size_t first = 0, group = 0; first < taken.size(); first += group) {
    group = std::min<std::size_t>(taken.size() - first, 1 + first % 8);  // groups of one to eight
    CellRunList lists[8];
    CellRunList* outs[8];
    for (int lane = 0; lane < 8; ++lane) outs[lane] = &lists[lane];
    triangle_cell_runs_in_eight_lanes(taken.data() + first, int(group), kFrame, outs);
    for (std::size_t lane = 0; lane < group; ++lane) {
      const TriangleCellVisit& v = *taken[first + lane];
      std::vector<std::array<std::uint32_t, 4>> expected, got;
      for_each_triangle_cell_run(v.a, v.b, v.c, kFrame, v.box_lower, v.box_upper, v.z_first, v.z_last,
                                 [&](std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
                                   expected.push_back({y, z, x_first, x_last});
                                 });
      for (std::uint32_t r = 0; r < lists[lane].count; ++r) {
        const CellRunList::Run& run = lists[lane].runs[r];
        got.push_back({run.y, run.z, run.x_first, run.x_last});
      }
      ASSERT_EQ(got, expected) << "visit " << (taken[first + lane] - visits.data());
      ++compared;
    }
  }
  EXPECT_EQ(compared, taken.size());

  // A batch hands on every visit's runs in the order the visits came, lanes or not.
  std::vector<std::array<std::uint32_t, 5>> expected, got;
  CellRunBatch batch;
  batch.use(KernelIsa::avx512);
  const auto into = [](auto& runs) {
    return [&runs](std::uint32_t t, std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
      runs.push_back({t, y, z, x_first, x_last});
    };
  };
  for (std::size_t i = 0; i < visits.size(); ++i) {
    const TriangleCellVisit& v = visits[i];
    const auto t = std::uint32_t(i);
    for_each_triangle_cell_run(v.a, v.b, v.c, kFrame, v.box_lower, v.box_upper, v.z_first, v.z_last,
                               [&](std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
                                 into(expected)(t, y, z, x_first, x_last);
                               });
    batch.add(t, v, kFrame, into(got));
  }
  batch.flush(kFrame, into(got));
  EXPECT_EQ(got, expected);
#else
  GTEST_SKIP() << "this build carries no AVX-512 kernels: the grids find their runs one triangle at a time";
#endif
}

}  // namespace
}  // namespace wavetrace
