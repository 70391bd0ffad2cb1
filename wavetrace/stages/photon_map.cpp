// The kd-tree over photon positions and the nearest-photon query, with the normal filter
// applied as photons are found (so the k are the k nearest that count).
#include "wavetrace/stages/photon_map.hpp"

#include <algorithm>
#include <array>
#include <limits>

#include <glm/geometric.hpp>
#include <nanoflann.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "wavetrace/kernels/morton.hpp"
#include "wavetrace/kernels/sampling.hpp"

namespace wavetrace {
namespace {

// nanoflann's view of the photons: positions only.
struct PhotonPositions {
  std::span<const Photon> photons;
  std::size_t kdtree_get_point_count() const { return photons.size(); }
  float kdtree_get_pt(std::size_t index, std::size_t axis) const { return photons[index].position[int(axis)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;  // computed by the tree
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PhotonPositions>,
                                                   PhotonPositions, 3, std::uint32_t>;

// A result set for nanoflann's search: the k nearest photons within a radius whose normal
// faces the query's side, kept sorted by squared distance in arrays on the stack.
class NearestPhotons {
 public:
  NearestPhotons(std::span<const Photon> photons, const glm::vec3& normal, std::uint32_t k, float max_distance_squared,
                 float min_cosine = 0.0f)
      : photons_(photons),
        normal_(normal),
        min_cosine_(min_cosine),
        capacity_(std::min(k, PhotonMap::kMaxNearest)),
        worst_(max_distance_squared) {}

  std::size_t size() const { return count_; }
  bool full() const { return count_ == capacity_; }
  float worstDist() const { return worst_; }  // the search skips what is farther
  bool addPoint(float distance_squared, std::uint32_t index) {
    if (distance_squared >= worst_ || glm::dot(photons_[index].normal, normal_) <= min_cosine_) return true;
    std::uint32_t slot = std::min(count_, capacity_ - 1);
    while (slot > 0 && distances_[slot - 1] > distance_squared) {
      distances_[slot] = distances_[slot - 1];
      indices_[slot] = indices_[slot - 1];
      --slot;
    }
    distances_[slot] = distance_squared;
    indices_[slot] = index;
    if (count_ < capacity_) ++count_;
    if (count_ == capacity_) worst_ = distances_[capacity_ - 1];
    return true;
  }

  std::uint32_t index(std::uint32_t i) const { return indices_[i]; }
  float radius_squared() const { return worst_; }  // the k-th's when full, else the bound

 private:
  std::span<const Photon> photons_;
  glm::vec3 normal_;
  float min_cosine_;
  std::uint32_t capacity_;
  std::uint32_t count_ = 0;
  float worst_;
  std::array<float, PhotonMap::kMaxNearest> distances_;
  std::array<std::uint32_t, PhotonMap::kMaxNearest> indices_;
};

}  // namespace

struct PhotonMap::Tree {
  explicit Tree(std::span<const Photon> photons)
      : positions{photons}, index(3, positions, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafPhotons)) {}
  // nanoflann's default, and the fastest of 4, 10, 24 and 48 photons a leaf on
  // scenes/caustic.toml (its estimates 3.3 s of thread time at 10, 3.4-4.4 s at the others).
  static constexpr std::size_t kLeafPhotons = 10;
  PhotonPositions positions;
  KdTree index;
};

PhotonMap::PhotonMap(PhotonArray photons) : photons_(std::move(photons)) {
  if (photons_.empty()) return;
  // Photons near in space near in memory: a search reads each candidate's position and
  // normal, and in key order (the order they landed) those are scattered over the array.
  glm::vec3 lower(std::numeric_limits<float>::max()), upper(std::numeric_limits<float>::lowest());
  for (const Photon& photon : photons_) {
    lower = glm::min(lower, photon.position);
    upper = glm::max(upper, photon.position);
  }
  const glm::vec3 scale = float((1u << 21) - 1) / glm::max(upper - lower, glm::vec3(1e-30f));
  LargeArray<std::pair<std::uint64_t, std::uint32_t>> order(photons_.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, photons_.size(), 4096), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const glm::vec3 cell = (photons_[i].position - lower) * scale;
      order[i] = {morton3d_encode(std::uint64_t(cell.x), std::uint64_t(cell.y), std::uint64_t(cell.z)),
                  std::uint32_t(i)};
    }
  });
  tbb::parallel_sort(order.begin(), order.end());  // (code, index) pairs are unique: one order
  PhotonArray sorted(photons_.size());
  for (std::size_t i = 0; i < order.size(); ++i) sorted[i] = photons_[order[i].second];
  photons_ = std::move(sorted);
  tree_ = std::make_unique<Tree>(photons_);
}

PhotonMap::~PhotonMap() = default;

glm::vec3 PhotonMap::irradiance(const glm::vec3& point, const glm::vec3& normal, std::uint32_t k,
                                float max_radius) const {
  if (tree_ == nullptr || k == 0) return glm::vec3(0.0f);
  NearestPhotons nearest(photons_, normal, k, max_radius * max_radius);
  const float query[3] = {point.x, point.y, point.z};
  tree_->index.findNeighbors(nearest, query, nanoflann::SearchParams());
  if (nearest.size() == 0) return glm::vec3(0.0f);
  glm::vec3 flux(0.0f);
  for (std::uint32_t i = 0; i < nearest.size(); ++i) flux += photons_[nearest.index(i)].power;
  return flux * (1.0f / (kPi * nearest.radius_squared()));
}

}  // namespace wavetrace

namespace wavetrace {

const Photon* PhotonMap::nearest(const glm::vec3& point, const glm::vec3& normal, float max_radius,
                                 float min_cosine) const {
  if (tree_ == nullptr) return nullptr;
  NearestPhotons nearest(photons_, normal, 1, max_radius * max_radius, min_cosine);
  const float query[3] = {point.x, point.y, point.z};
  tree_->index.findNeighbors(nearest, query, nanoflann::SearchParams());
  return nearest.size() == 0 ? nullptr : &photons_[nearest.index(0)];
}

void PhotonMap::precompute_irradiance(std::uint32_t stride, std::uint32_t k, float max_radius) {
  PhotonArray points((photons_.size() + stride - 1) / stride);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1024), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const Photon& at = photons_[i * stride];
      points[i] = Photon{at.position, irradiance(at.position, at.normal, k, max_radius), at.normal};
    }
  });
  precomputed_ = std::make_unique<PhotonMap>(std::move(points));
}

glm::vec3 PhotonMap::precomputed_irradiance(const glm::vec3& point, const glm::vec3& normal, std::uint32_t k,
                                            float max_radius) const {
  // Surfaces within 25 degrees share an estimate (Christensen's normal test).
  constexpr float kSameSurfaceCosine = 0.906f;
  if (precomputed_ != nullptr) {
    if (const Photon* near = precomputed_->nearest(point, normal, max_radius, kSameSurfaceCosine)) return near->power;
  }
  return irradiance(point, normal, k, max_radius);
}

}  // namespace wavetrace
