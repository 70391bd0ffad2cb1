// Each chunk simplified and judged on the thread that built it; the pieces joined at the end.
#include "wavetrace/accel/proxy/proxy_by_chunks.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "wavetrace/accel/proxy/cluster_simplify.hpp"
#include "wavetrace/accel/proxy/stochastic_simplify.hpp"

namespace wavetrace {
namespace {

// Test rays a chunk's candidates are judged on: fewer than a whole mesh's 16,384, since every
// chunk is judged and its rays stay in its own box.
constexpr std::size_t kChunkTestRays = 4096;

}  // namespace

ProxyByChunks::ProxyByChunks(const ProxyOptions& options) : options_(options) {
  check_proxy_share(options.share);
}

void ProxyByChunks::add(std::size_t chunk, std::size_t first, const TriangleMesh& mesh, const Accelerator& built) {
  const auto start = std::chrono::steady_clock::now();
  Piece piece;
  piece.scene_triangles = mesh.triangle_count();
  piece.diagonal = mesh.bounds().diagonal();
  const std::size_t target = proxy_target_triangles(options_.share, mesh.triangle_count());
  ClusterSimplification clustered = simplify_by_clustering(mesh, target);
  piece.cell_size = clustered.cell_size;  // the scale of either method, as for a whole mesh
  const auto judge = [&](const TriangleMesh& candidate) -> std::optional<ProxyQuality> {
    if (candidate.triangles.empty()) return std::nullopt;
    const auto accelerator = make_accelerator(candidate, options_.accelerator);
    return measure_proxy_quality(*accelerator, built, mesh.bounds(), kChunkTestRays);
  };
  TriangleMesh cluster_mesh, stochastic_mesh;
  if (options_.method != ProxyMethod::stochastic) cluster_mesh = cleaned_proxy_mesh(std::move(clustered.mesh));
  if (options_.method != ProxyMethod::cluster) {
    stochastic_mesh = cleaned_proxy_mesh(simplify_stochastically(mesh, options_.share, first));
  }
  const std::optional<ProxyQuality> cluster_quality = judge(cluster_mesh), stochastic_quality = judge(stochastic_mesh);
  const bool cluster_wins = clustering_wins(cluster_quality, stochastic_quality);
  piece.method = cluster_wins ? ProxyMethod::cluster : ProxyMethod::stochastic;
  piece.mesh = std::move(cluster_wins ? cluster_mesh : stochastic_mesh);
  if (const std::optional<ProxyQuality>& quality = cluster_wins ? cluster_quality : stochastic_quality) piece.quality = *quality;
  piece.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::lock_guard lock(mutex_);
  pieces_[chunk] = std::move(piece);
}

std::unique_ptr<Proxy> ProxyByChunks::finish(const Bounds3& scene_bounds) {
  TriangleMesh joined;
  ProxyReport report;
  double tolerance = 0.0, weight = 0.0, cluster_triangles = 0.0, stochastic_triangles = 0.0;
  const double scene_diagonal = std::max(double(scene_bounds.diagonal()), 1e-30);
  for (const auto& [chunk, piece] : pieces_) {
    const auto offset = static_cast<std::uint32_t>(joined.positions.size());
    joined.positions.insert(joined.positions.end(), piece.mesh.positions.begin(), piece.mesh.positions.end());
    for (const glm::uvec3& triangle : piece.mesh.triangles) joined.triangles.push_back(triangle + offset);
    tolerance = std::max(tolerance, piece.cell_size);
    report.simplify_seconds += piece.seconds;
    (piece.method == ProxyMethod::cluster ? cluster_triangles : stochastic_triangles) += double(piece.mesh.triangle_count());
    const double w = double(piece.scene_triangles);
    weight += w;
    report.quality.hit_agreement += w * piece.quality.hit_agreement;
    report.quality.hit_overlap += w * piece.quality.hit_overlap;
    report.quality.mean_distance_error += w * piece.quality.mean_distance_error * piece.diagonal / scene_diagonal;
  }
  if (joined.triangles.empty()) throw SceneError("the proxy lost every triangle: raise proxy.share");
  if (weight > 0.0) {
    report.quality.hit_agreement /= weight;
    report.quality.hit_overlap /= weight;
    report.quality.mean_distance_error /= weight;
  }
  report.method = cluster_triangles >= stochastic_triangles ? ProxyMethod::cluster : ProxyMethod::stochastic;
  report.triangles = joined.triangle_count();
  pieces_.clear();
  return std::make_unique<Proxy>(std::move(joined), scene_bounds, static_cast<float>(tolerance), report,
                                 options_.accelerator);
}

}  // namespace wavetrace
