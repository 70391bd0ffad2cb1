// Simplify, judge, keep, and build the proxy's accelerator.
#include "wavetrace/accel/proxy/proxy.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "wavetrace/accel/proxy/cluster_simplify.hpp"
#include "wavetrace/accel/proxy/stochastic_simplify.hpp"
#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/sampling.hpp"

namespace wavetrace {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

ProxyMethod parse_proxy_method(const std::string& text) {
  if (text == "auto") return ProxyMethod::automatic;
  if (text == "cluster") return ProxyMethod::cluster;
  if (text == "stochastic") return ProxyMethod::stochastic;
  throw std::invalid_argument("unknown proxy method '" + text + "' (known: auto, cluster, stochastic)");
}

std::string to_string(ProxyMethod method) {
  switch (method) {
    case ProxyMethod::automatic: return "auto";
    case ProxyMethod::cluster: return "cluster";
    case ProxyMethod::stochastic: return "stochastic";
  }
  return "?";
}

ProxyQuality measure_proxy_quality(const Accelerator& candidate, const Accelerator& scene_accelerator,
                                   const Bounds3& scene_bounds, std::size_t rays) {
  constexpr std::size_t kBatch = kDefaultBatchCapacity;
  const float diagonal = scene_bounds.diagonal();
  const std::size_t batches = (rays + kBatch - 1) / kBatch;
  std::vector<std::size_t> agree(batches, 0), both(batches, 0), either(batches, 0);
  std::vector<double> error(agree.size(), 0.0);
  tbb::parallel_for(std::size_t{0}, agree.size(), [&](std::size_t b) {
    RayBatch batch(kBatch);
    HitBatch scene_hits(kBatch), candidate_hits(kBatch);
    batch.count = std::min(kBatch, rays - b * kBatch);
    for (std::size_t i = 0; i < batch.count; ++i) {
      const auto id = static_cast<std::uint32_t>(b * kBatch + i);
      const UnitPair xy = unit_pair(random_bits(id, 0, 0, RandomPurpose::simplification));
      const UnitPair zd = unit_pair(random_bits(id, 0, 1, RandomPurpose::simplification));
      const UnitPair d = unit_pair(random_bits(id, 0, 2, RandomPurpose::simplification));
      const glm::vec3 origin = scene_bounds.lower + scene_bounds.extent() * glm::vec3(xy.first, xy.second, zd.first);
      batch.set_geometry(i, origin, uniform_sphere(d.first, d.second), 0.0f, std::numeric_limits<float>::infinity());
      batch.flags[i] = ray_flags::alive;
      batch.kind[i] = RayKind::bounce;
    }
    scene_accelerator.intersect_closest(batch, scene_hits, batch.all());
    candidate.intersect_closest(batch, candidate_hits, batch.all());
    for (std::size_t i = 0; i < batch.count; ++i) {
      const bool scene_hit = scene_hits.is_hit(i), candidate_hit = candidate_hits.is_hit(i);
      agree[b] += scene_hit == candidate_hit;
      either[b] += scene_hit || candidate_hit;
      if (scene_hit && candidate_hit) {
        ++both[b];
        error[b] += std::fabs(double(scene_hits.t[i]) - double(candidate_hits.t[i])) / diagonal;
      }
    }
  });
  std::size_t agreed = 0, hit_both = 0, hit_either = 0;
  double error_sum = 0.0;
  for (std::size_t b = 0; b < batches; ++b) {
    agreed += agree[b];
    hit_both += both[b];
    hit_either += either[b];
    error_sum += error[b];
  }
  return {double(agreed) / double(std::max<std::size_t>(rays, 1)),
          hit_either ? double(hit_both) / double(hit_either) : 1.0, hit_both ? error_sum / double(hit_both) : 0.0};
}

TriangleMesh cleaned_proxy_mesh(TriangleMesh simplified) {
  try {
    validate_and_clean(simplified, "proxy");
  } catch (const SceneError&) {
    return TriangleMesh{};
  }
  return simplified;
}

void check_proxy_share(double share) {
  if (!(share > 0.0 && share <= 1.0)) throw SceneError(fmt::format("proxy share {} must be in (0, 1]", share));
}

std::size_t proxy_target_triangles(double share, std::size_t mesh_triangles) {
  return static_cast<std::size_t>(std::max(4.0, std::round(share * double(mesh_triangles))));
}

bool clustering_wins(const std::optional<ProxyQuality>& cluster, const std::optional<ProxyQuality>& stochastic) {
  return cluster && (!stochastic || cluster->hit_overlap >= stochastic->hit_overlap);
}

Proxy::Proxy(const TriangleMesh& mesh, const ProxyOptions& options, const Accelerator& scene_accelerator)
    : scene_bounds_(mesh.bounds()) {
  check_proxy_share(options.share);
  const std::size_t target = proxy_target_triangles(options.share, mesh.triangle_count());
  const auto start = std::chrono::steady_clock::now();
  double cell_size = 0.0;
  const auto clustered = [&] {
    ClusterSimplification simplified = simplify_by_clustering(mesh, target);
    cell_size = simplified.cell_size;
    return cleaned_proxy_mesh(std::move(simplified.mesh));
  };
  const auto pruned = [&] { return cleaned_proxy_mesh(simplify_stochastically(mesh, options.share)); };

  if (options.method == ProxyMethod::automatic) {
    TriangleMesh cluster_mesh = clustered(), stochastic_mesh = pruned();
    report_.simplify_seconds = seconds_since(start);
    const auto judge = [&](const TriangleMesh& candidate) -> std::optional<ProxyQuality> {
      if (candidate.triangles.empty()) return std::nullopt;
      const auto accelerator = make_accelerator(candidate, options.accelerator);
      return measure_proxy_quality(*accelerator, scene_accelerator, scene_bounds_);
    };
    report_.cluster_quality = judge(cluster_mesh);
    report_.stochastic_quality = judge(stochastic_mesh);
    const bool cluster_wins = clustering_wins(report_.cluster_quality, report_.stochastic_quality);
    report_.method = cluster_wins ? ProxyMethod::cluster : ProxyMethod::stochastic;
    mesh_ = std::move(cluster_wins ? cluster_mesh : stochastic_mesh);
  } else {
    report_.method = options.method;
    mesh_ = options.method == ProxyMethod::cluster ? clustered() : pruned();
    report_.simplify_seconds = seconds_since(start);
  }
  if (mesh_.triangles.empty()) throw SceneError("the proxy lost every triangle: raise proxy.share");
  if (cell_size == 0.0) cell_size = simplify_by_clustering(mesh, target).cell_size;  // the scale of either method
  surface_tolerance_ = static_cast<float>(cell_size);
  const auto build_start = std::chrono::steady_clock::now();
  accelerator_ = make_accelerator(mesh_, options.accelerator);
  report_.build_seconds = seconds_since(build_start);
  report_.triangles = mesh_.triangle_count();
  if (options.method != ProxyMethod::automatic) {
    report_.quality = measure_proxy_quality(*accelerator_, scene_accelerator, scene_bounds_);
  } else {
    report_.quality = report_.method == ProxyMethod::cluster ? *report_.cluster_quality : *report_.stochastic_quality;
  }
}

Proxy::Proxy(const Proxy& finer, std::size_t target, const AcceleratorOptions& accelerator,
             const Accelerator* scene_accelerator)
    : scene_bounds_(finer.scene_bounds_) {
  const auto start = std::chrono::steady_clock::now();
  report_.method = finer.report_.method;
  report_.coarsened_from = finer.report_.triangles;
  // A stochastic proxy stands for aggregate detail (fur) that clustering would merge into
  // blobs: it is pruned again. The cell size of a clustering of the finer proxy is the new
  // surface tolerance either way, never below the finer one's.
  ClusterSimplification clustered = simplify_by_clustering(finer.mesh_, target);
  if (report_.method == ProxyMethod::stochastic) {
    const double share = double(target) / double(std::max<std::size_t>(finer.mesh_.triangle_count(), 1));
    mesh_ = cleaned_proxy_mesh(simplify_stochastically(finer.mesh_, share));
  } else {
    mesh_ = cleaned_proxy_mesh(std::move(clustered.mesh));
  }
  if (mesh_.triangles.empty()) throw SceneError("the proxy lost every triangle when coarsened: raise proxy.share");
  surface_tolerance_ = std::max(finer.surface_tolerance_, static_cast<float>(clustered.cell_size));
  report_.simplify_seconds = seconds_since(start);
  const auto build_start = std::chrono::steady_clock::now();
  accelerator_ = make_accelerator(mesh_, accelerator);
  report_.build_seconds = seconds_since(build_start);
  report_.triangles = mesh_.triangle_count();
  report_.judged_against_saved = scene_accelerator == nullptr;
  report_.quality = measure_proxy_quality(*accelerator_, scene_accelerator ? *scene_accelerator : *finer.accelerator_,
                                          scene_bounds_);
}

Proxy::Proxy(TriangleMesh simplified, const Bounds3& scene_bounds, float surface_tolerance, const ProxyReport& report,
             const AcceleratorOptions& accelerator)
    : mesh_(std::move(simplified)), scene_bounds_(scene_bounds), report_(report), surface_tolerance_(surface_tolerance) {
  if (mesh_.triangles.empty()) throw SceneError("the saved proxy has no triangles");
  const auto build_start = std::chrono::steady_clock::now();
  accelerator_ = make_accelerator(mesh_, accelerator);
  report_.build_seconds = seconds_since(build_start);
}

}  // namespace wavetrace
