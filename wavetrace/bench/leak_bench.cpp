// Inside points by unanimous ray parity along three skew directions (robust Embree), or
// uniform in a scene's enclosure; then the same rays traced by every accelerator.
#include "wavetrace/bench/leak_bench.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/sampling.hpp"
#include "wavetrace/scene/mesh_report.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/pipeline/tracing_arena.hpp"

namespace wavetrace {
namespace {

constexpr std::size_t kBatch = kDefaultBatchCapacity;

// Crossings of the surface along a ray from `origin`, counted one hit at a time.
std::size_t crossings(const Accelerator& reference, const glm::vec3& origin, const glm::vec3& direction, float step) {
  RayBatch ray(1);
  HitBatch hit(1);
  ray.count = 1;
  ray.set_geometry(0, origin, direction, 0.0f, std::numeric_limits<float>::infinity());
  ray.flags[0] = ray_flags::alive;
  ray.kind[0] = RayKind::camera;
  float tmin = 0.0f;
  std::size_t count = 0;
  for (; count < 10000; ++count) {
    ray.tmin[0] = tmin;
    reference.intersect_closest(ray, hit, ray.all());
    if (!hit.is_hit(0)) break;
    tmin = hit.t[0] + step;
  }
  return count;
}

std::vector<glm::vec3> inside_points(const TriangleMesh& mesh, const std::string& name, const Accelerator& reference,
                                     std::size_t wanted) {
  const Bounds3 bounds = mesh.bounds();
  const float step = 1e-6f * bounds.diagonal();
  const glm::vec3 directions[3] = {glm::normalize(glm::vec3(1.0f, 0.1234f, 0.0567f)),
                                   glm::normalize(glm::vec3(-0.0789f, 1.0f, 0.1357f)),
                                   glm::normalize(glm::vec3(0.0246f, -0.1593f, 1.0f))};
  std::vector<glm::vec3> points;
  const std::size_t candidates_per_round = 4 * wanted;
  for (std::uint32_t round = 0; points.size() < wanted && round < 16; ++round) {
    std::vector<char> inside(candidates_per_round, 0);
    std::vector<glm::vec3> candidates(candidates_per_round);
    tbb::parallel_for(std::size_t{0}, candidates_per_round, [&](std::size_t c) {
      const auto id = static_cast<std::uint32_t>(c);
      const UnitPair xy = unit_pair(random_bits(id, round, 0, RandomPurpose::benchmark));
      const float z = unit_float(random_bits(id, round, 1, RandomPurpose::benchmark));
      candidates[c] = bounds.lower + bounds.extent() * glm::vec3(xy.first, xy.second, z);
      bool odd_everywhere = true;
      for (const glm::vec3& direction : directions) odd_everywhere &= crossings(reference, candidates[c], direction, step) % 2 == 1;
      inside[c] = odd_everywhere;
    });
    for (std::size_t c = 0; c < candidates_per_round && points.size() < wanted; ++c) {
      if (inside[c]) points.push_back(candidates[c]);
    }
  }
  if (points.empty()) throw std::runtime_error(name + ": found no point inside the mesh");
  return points;
}

// Uniform points inside the enclosure, kept off its walls by a thousandth of its extent
// plus `extra_margin` (how far a lossy accelerator moved the walls).
std::vector<glm::vec3> enclosed_points(const Bounds3& enclosure, std::size_t wanted, float extra_margin = 0.0f) {
  const glm::vec3 margin = enclosure.extent() * 1e-3f + extra_margin;
  const glm::vec3 lower = enclosure.lower + margin, extent = enclosure.extent() - 2.0f * margin;
  std::vector<glm::vec3> points(wanted);
  for (std::size_t p = 0; p < wanted; ++p) {
    const auto id = static_cast<std::uint32_t>(p);
    const UnitPair xy = unit_pair(random_bits(id, 0, 0, RandomPurpose::benchmark));
    const float z = unit_float(random_bits(id, 0, 1, RandomPurpose::benchmark));
    points[p] = lower + extent * glm::vec3(xy.first, xy.second, z);
  }
  return points;
}

}  // namespace

LeakReport run_leak_bench(const Scene& scene, const std::vector<AcceleratorSpec>& accelerators, std::size_t count,
                          int threads) {
  const MeshReport topology = analyze_mesh(scene.mesh);
  if (!topology.closed() && !scene.enclosure) {
    throw std::runtime_error(fmt::format("{}: the leak test needs a closed mesh or an enclosing shell, and this one "
                                         "has {} boundary and {} non-manifold edges",
                                         scene.name, topology.boundary_edges, topology.non_manifold_edges));
  }
  LeakReport report;
  report.scene = scene.name;
  report.triangles = scene.mesh.triangle_count();
  TracingArena arena(threads);
  arena.execute([&] {
    AcceleratorOptions robust;
    robust.embree.mode = EmbreeMode::robust;
    const auto reference = make_accelerator(scene.mesh, robust);
    const std::size_t wanted = std::min<std::size_t>(count, 4096);
    report.enclosure = !topology.closed();
    const std::vector<glm::vec3> points =
        report.enclosure ? enclosed_points(*scene.enclosure, wanted) : inside_points(scene.mesh, scene.name, *reference, wanted);
    report.inside_points = points.size();

    for (const AcceleratorSpec& spec : accelerators) {
      const auto accelerator = build_world_accelerator(scene, spec.options);
      // A lossy accelerator answers for a moved surface: a point is asked to be inside that.
      LeakResult result{spec.label, count, 0, false};
      std::vector<glm::vec3> own_points;
      if (const std::optional<TriangleMesh> represented = accelerator->represented_mesh(scene.mesh)) {
        result.own_surface = true;
        if (report.enclosure) {
          float moved = 0.0f;
          for (std::size_t v = 0; v < represented->vertex_count(); ++v) {
            moved = std::max(moved, glm::length(represented->positions[v] - scene.mesh.positions[v]));
          }
          own_points = enclosed_points(*scene.enclosure, wanted, 2.0f * moved);
        } else {
          const auto own_reference = make_accelerator(*represented, robust);
          own_points = inside_points(*represented, scene.name, *own_reference, wanted);
        }
      }
      const std::vector<glm::vec3>& origins = result.own_surface ? own_points : points;
      std::vector<std::size_t> escaped((count + kBatch - 1) / kBatch, 0);
      tbb::parallel_for(std::size_t{0}, escaped.size(), [&](std::size_t b) {
        RayBatch rays(kBatch);
        HitBatch hits(kBatch);
        rays.count = std::min(kBatch, count - b * kBatch);
        for (std::size_t i = 0; i < rays.count; ++i) {
          const auto id = static_cast<std::uint32_t>(b * kBatch + i);
          const glm::vec3& origin = origins[id % origins.size()];
          const UnitPair u = unit_pair(random_bits(id, 0, 3, RandomPurpose::benchmark));
          rays.set_geometry(i, origin, uniform_sphere(u.first, u.second), 0.0f, std::numeric_limits<float>::infinity());
          rays.flags[i] = ray_flags::alive;
          rays.kind[i] = RayKind::camera;
        }
        accelerator->intersect_closest(rays, hits, rays.all());
        for (std::size_t i = 0; i < rays.count; ++i) escaped[b] += !hits.is_hit(i);
      });
      for (std::size_t e : escaped) result.escaped += e;
      report.results.push_back(result);
    }
  });
  return report;
}

nlohmann::json to_json(const LeakReport& report) {
  nlohmann::json results = nlohmann::json::array();
  for (const LeakResult& r : report.results) {
    results.push_back({{"accel", r.label}, {"rays", r.rays}, {"escaped", r.escaped},
                       {"points_inside", r.own_surface ? "its own surface" : "the mesh"}});
  }
  return {{"scene", {{"source", report.scene}, {"triangles", report.triangles}}},
          {"inside_points", report.inside_points},
          {"points_from", report.enclosure ? "enclosure" : "parity"},
          {"results", results}};
}

std::string to_table(const LeakReport& report) {
  std::string table = fmt::format("{}: {} triangles; rays from {} points inside {}\n", report.scene, report.triangles,
                                  report.inside_points, report.enclosure ? "the enclosing shell" : "the closed mesh");
  table += fmt::format("{:<24} {:>12} {:>10}\n", "accel", "rays", "escaped");
  for (const LeakResult& r : report.results) {
    table += fmt::format("{:<24} {:>12} {:>10}{}\n", r.label, r.rays, r.escaped,
                         r.own_surface ? "   (from points inside its own, quantized surface)" : "");
  }
  return table;
}

}  // namespace wavetrace
