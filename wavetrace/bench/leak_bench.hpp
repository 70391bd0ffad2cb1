// `wavetrace bench leak`: rays from random points strictly inside a closed surface, in random
// directions. Every such ray must hit the surface; one that finds nothing has slipped
// through a crack between triangles (a watertightness failure).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/scene/scene.hpp"

namespace wavetrace {

struct LeakResult {
  std::string label;
  std::size_t rays = 0;
  std::size_t escaped = 0;
  // A lossy accelerator (Accelerator::represented_mesh) is shot at from points inside the
  // surface it represents, which may differ from the mesh's near its walls.
  bool own_surface = false;
};

struct LeakReport {
  std::string scene;
  std::size_t triangles = 0;
  std::size_t inside_points = 0;
  bool enclosure = false;  // points drawn in the scene's enclosure, not found by ray parity
  std::vector<LeakResult> results;
};

// A closed mesh gets points inside it; an open one with an enclosure (builtin:room) gets
// points anywhere in the enclosure. Throws std::runtime_error naming the reason when the
// scene is neither, or when no inside point is found.
LeakReport run_leak_bench(const Scene& scene, const std::vector<AcceleratorSpec>& accelerators, std::size_t count,
                          int threads);

nlohmann::json to_json(const LeakReport& report);
std::string to_table(const LeakReport& report);

}  // namespace wavetrace
