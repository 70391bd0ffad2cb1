// The photon map (Jensen 1996): photons left on diffuse surfaces, in a kd-tree (nanoflann's,
// Debian's libnanoflann-dev), answering the k-nearest irradiance estimate. Built once after
// the photon pass and read-only while the camera pass runs.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "wavetrace/memory/cache_aligned_allocator.hpp"

#include <glm/vec3.hpp>

namespace wavetrace {

// One photon at rest (36 bytes, in memory only): where it landed, the flux it carries (the
// scene's emission units times area), and the unit normal of the surface on the side it came
// from, so an estimate takes no photon from the far side of a thin wall.
struct Photon {
  glm::vec3 position;
  glm::vec3 power;
  glm::vec3 normal;
};

// A map's photons: tens of MB, on huge pages (their first touch in 4 KiB faults took half of
// the maps' build on builtin:room:1M; docs/measurements.md).
using PhotonArray = LargeArray<Photon>;

class PhotonMap {
 public:
  // The most photons one estimate gathers (photon.k's bound): a query keeps them on its stack.
  static constexpr std::uint32_t kMaxNearest = 1024;

  explicit PhotonMap(PhotonArray photons);
  ~PhotonMap();
  PhotonMap(const PhotonMap&) = delete;
  PhotonMap& operator=(const PhotonMap&) = delete;

  std::size_t size() const { return photons_.size(); }
  std::span<const Photon> photons() const { return photons_; }

  // Irradiance at `point` on a surface of unit `normal`: the flux of the `k` nearest photons
  // within `max_radius` that arrived on the normal's side, over pi r^2, r the distance of the
  // k-th (max_radius when fewer are that near). Deterministic: the tree is built from the
  // photons in the order given.
  glm::vec3 irradiance(const glm::vec3& point, const glm::vec3& normal, std::uint32_t k, float max_radius) const;

  // The photon nearest `point` within `max_radius` whose normal is within acos(min_cosine) of
  // `normal`; null if none.
  const Photon* nearest(const glm::vec3& point, const glm::vec3& normal, float max_radius, float min_cosine) const;

  // Christensen's precomputed irradiance ("Faster photon map global illumination", 1999): the
  // estimate made once at every `stride`-th photon, in parallel, and kept as a map of its own,
  // so that a gathering ray reads the nearest instead of searching for k photons.
  void precompute_irradiance(std::uint32_t stride, std::uint32_t k, float max_radius);
  bool has_precomputed() const { return precomputed_ != nullptr; }
  std::size_t precomputed_count() const { return precomputed_ != nullptr ? precomputed_->size() : 0; }
  // The precomputed irradiance nearest `point` on a surface facing about as `normal` does
  // (within 25 degrees); where none is within `max_radius`, the full estimate.
  glm::vec3 precomputed_irradiance(const glm::vec3& point, const glm::vec3& normal, std::uint32_t k,
                                   float max_radius) const;

 private:
  struct Tree;
  PhotonArray photons_;
  std::unique_ptr<Tree> tree_;
  std::unique_ptr<PhotonMap> precomputed_;  // power holds the irradiance there
};

// The camera pass's maps and how it reads them (photon.k, photon.radius resolved; with
// photon.precompute > 0 the global map's irradiance precomputed at every that many photons).
struct PhotonMaps {
  PhotonMaps(PhotonArray global_photons, PhotonArray caustic_photons, std::uint32_t nearest,
             float max_radius, std::uint32_t precompute_stride)
      : global(std::move(global_photons)), caustic(std::move(caustic_photons)), k(nearest), radius(max_radius) {
    if (precompute_stride > 0) global.precompute_irradiance(precompute_stride, k, radius);
  }
  PhotonMap global;   // every landing: read where a gathering ray ends
  PhotonMap caustic;  // landings by specular paths alone: read where a camera path meets a diffuse surface
  std::uint32_t k;
  float radius;
};

}  // namespace wavetrace
