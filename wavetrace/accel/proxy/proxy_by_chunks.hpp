// The proxy of a world built streamed, chunk by chunk, so that the scene is never held whole
// (a billion triangles, or a world larger than memory): each chunk's mesh is simplified by
// itself while the chunk is built, and the pieces are joined in chunk order when it is done.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <mutex>

#include "wavetrace/accel/proxy/proxy.hpp"

namespace wavetrace {

// Collects a proxy from the chunks a streamed build reports (ChunkObserver). Against the proxy
// of the whole mesh:
// - a chunk is simplified to proxy.share of its own triangles, on a clustering grid sized for
//   it, so a cell cut by a chunk's boundary gets a vertex on either side: cracks of about a
//   cell, the distance approx_hit already allows (Proxy::surface_tolerance, here the largest
//   chunk's cell);
// - stochastic pruning keeps exactly the triangles it keeps from the whole mesh (it hashes the
//   scene's triangle ids);
// - under auto each chunk keeps the method whose hits overlap its own accelerator's more, so the
//   fur's chunks may prune while the walls' cluster; the report names the method most triangles
//   came from;
// - the quality is measured per chunk, against the chunk, on rays from its box, and reported
//   as the mean over chunks weighted by their triangles (distance errors scaled to the scene's
//   diagonal), since the streamed world cannot be traced whole while it is built.
class ProxyByChunks {
 public:
  // Throws SceneError for a share outside (0, 1].
  explicit ProxyByChunks(const ProxyOptions& options);
  // One chunk's piece; thread-safe for distinct chunks.
  void add(std::size_t chunk, std::size_t first, const TriangleMesh& mesh, const Accelerator& built);
  bool empty() const { return pieces_.empty(); }
  // The proxy from every piece added; throws SceneError when every chunk lost its triangles.
  std::unique_ptr<Proxy> finish(const Bounds3& scene_bounds);

 private:
  struct Piece {
    TriangleMesh mesh;
    ProxyMethod method = ProxyMethod::cluster;
    ProxyQuality quality;
    double cell_size = 0.0, diagonal = 0.0, seconds = 0.0;
    std::size_t scene_triangles = 0;
  };
  ProxyOptions options_;
  std::mutex mutex_;
  std::map<std::size_t, Piece> pieces_;  // by chunk, so that they join in chunk order
};

}  // namespace wavetrace
