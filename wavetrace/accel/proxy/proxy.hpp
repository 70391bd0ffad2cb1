// The proxy of the reordering paper (§4.2): the scene simplified to a small share of its
// triangles with an accelerator of its own, queried by approx_hit for approximate hit
// points. Its box is the scene's, so a ray that misses the box misses the scene.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// cluster: vertex clustering with quadrics (cluster_simplify.hpp). stochastic: stochastic
// pruning (stochastic_simplify.hpp). auto: both, keeping the one whose hits overlap the
// scene's more on test rays (the fallback for aggregate detail such as fur).
enum class ProxyMethod { automatic, cluster, stochastic };
ProxyMethod parse_proxy_method(const std::string& text);  // "auto" | "cluster" | "stochastic"
std::string to_string(ProxyMethod method);

struct ProxyOptions {
  // proxy.share = auto chooses by where the world is held. Paged (a memory budget), or saved by
  // `wavetrace build` to be paged later: the paper's 2%, whose closer hits save reads. In core
  // a proxy's walk is a larger part of the render and a coarser one orders the rays as well
  // (docs/reordering.md, "The proxy in core").
  static constexpr double kPagedShare = 0.02;
  static constexpr double kInCoreShare = 0.002;
  double share = kPagedShare;  // of the scene's triangles; the paper: 2% (0.0125%-8% workable)
  bool share_by_holding = true;  // auto: plan_render sets `share` from the memory plan
  ProxyMethod method = ProxyMethod::automatic;
  AcceleratorOptions accelerator;
  bool operator==(const ProxyOptions&) const = default;
};

// How well a proxy stands in for the scene on rays from random points of the scene's box
// in random directions (a stand-in for bounce rays).
struct ProxyQuality {
  double hit_agreement = 0.0;       // both hit or both miss
  // Rays both hit over rays either hits: the agreement that matters for ordering, since
  // rays missing both are common and easy.
  double hit_overlap = 0.0;
  double mean_distance_error = 0.0; // |t_proxy - t_scene| / scene diagonal, where both hit
};

struct ProxyReport {
  ProxyMethod method = ProxyMethod::cluster;  // the one used
  std::size_t triangles = 0;
  double simplify_seconds = 0.0;
  double build_seconds = 0.0;  // of the proxy's accelerator
  ProxyQuality quality;
  std::optional<ProxyQuality> cluster_quality, stochastic_quality;  // measured under auto
  std::size_t coarsened_from = 0;  // a saved proxy's triangles, where this one was simplified from it; else 0
  // `quality` against the saved proxy's hits, not the scene's: where the process does not hold
  // the whole world to judge by (a data-parallel rank).
  bool judged_against_saved = false;
};

class Proxy {
 public:
  // `scene_accelerator` answers for the full mesh; it judges quality. Throws SceneError
  // when the share is outside (0, 1].
  Proxy(const TriangleMesh& mesh, const ProxyOptions& options, const Accelerator& scene_accelerator);
  // A proxy simplified before (a saved world's): its accelerator is rebuilt from `simplified`,
  // everything else is as it was.
  Proxy(TriangleMesh simplified, const Bounds3& scene_bounds, float surface_tolerance, const ProxyReport& report,
        const AcceleratorOptions& accelerator);
  // `finer` (a saved world's) simplified again, by its own method, to about `target`
  // triangles; its quality measured against `scene_accelerator` as a new proxy's is, or,
  // where that is null, against `finer`.
  Proxy(const Proxy& finer, std::size_t target, const AcceleratorOptions& accelerator,
        const Accelerator* scene_accelerator);

  const Accelerator& accelerator() const { return *accelerator_; }
  const Bounds3& scene_bounds() const { return scene_bounds_; }
  const TriangleMesh& mesh() const { return mesh_; }
  const ProxyReport& report() const { return report_; }
  // How far the proxy's surface may lie from the scene's: about one simplification cell.
  // A ray leaving the scene's surface would hit the proxy right there; approx_hit skips
  // this distance from each origin so the approximate hit is the one further along.
  float surface_tolerance() const { return surface_tolerance_; }

 private:
  TriangleMesh mesh_;
  std::unique_ptr<Accelerator> accelerator_;
  Bounds3 scene_bounds_;
  ProxyReport report_;
  float surface_tolerance_ = 0.0f;
};

// Throws SceneError for a share outside (0, 1].
void check_proxy_share(double share);
// The triangles a simplification aims for: the share of the mesh's, at least a tetrahedron's.
std::size_t proxy_target_triangles(double share, std::size_t mesh_triangles);
// A simplification's mesh cleaned as a scene's is, or empty where the method lost every
// triangle (an empty result marks a method that failed there).
TriangleMesh cleaned_proxy_mesh(TriangleMesh simplified);
// auto's rule: clustering unless stochastic pruning's hits overlap the scene's more (or only
// it kept triangles). Each quality is empty where its method kept none.
bool clustering_wins(const std::optional<ProxyQuality>& cluster, const std::optional<ProxyQuality>& stochastic);

// Hit agreement of `candidate` with `scene_accelerator` on `rays` test rays.
ProxyQuality measure_proxy_quality(const Accelerator& candidate, const Accelerator& scene_accelerator,
                                   const Bounds3& scene_bounds, std::size_t rays = 16384);

}  // namespace wavetrace
