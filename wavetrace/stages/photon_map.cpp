// The kd-tree over photon positions and the nearest-photon query, with the normal filter
// applied as photons are found (so the k are the k nearest that count).
#include "wavetrace/stages/photon_map.hpp"

#include <algorithm>
#include <array>
#include <limits>

#include <glm/geometric.hpp>
#include <nanoflann.hpp>

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
  NearestPhotons(std::span<const Photon> photons, const glm::vec3& normal, std::uint32_t k, float max_distance_squared)
      : photons_(photons), normal_(normal), capacity_(std::min(k, PhotonMap::kMaxNearest)), worst_(max_distance_squared) {}

  std::size_t size() const { return count_; }
  bool full() const { return count_ == capacity_; }
  float worstDist() const { return worst_; }  // the search skips what is farther
  bool addPoint(float distance_squared, std::uint32_t index) {
    if (distance_squared >= worst_ || glm::dot(photons_[index].normal, normal_) <= 0.0f) return true;
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
  // nanoflann's default; leaves of 10 photons balance its depth against the scan of a leaf.
  static constexpr std::size_t kLeafPhotons = 10;
  PhotonPositions positions;
  KdTree index;
};

PhotonMap::PhotonMap(std::vector<Photon> photons) : photons_(std::move(photons)) {
  if (!photons_.empty()) tree_ = std::make_unique<Tree>(photons_);
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
