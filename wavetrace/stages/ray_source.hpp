// Where a chain's new rays come from: camera rays (generate) or photons leaving the lights
// (emit_photons). The pipeline's generate node claims ranges of a source's rays and fills a
// batch with each, from any number of threads at once; a ray is a pure function of its index.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

class RaySource {
 public:
  virtual ~RaySource() = default;
  virtual std::string name() const = 0;
  virtual std::uint64_t total_rays() const = 0;
  virtual std::uint64_t generated() const = 0;  // rays claimed so far
  virtual bool exhausted() const = 0;

  // Claims the next rays, up to `capacity`: their first index and count (0 when every ray is
  // claimed). Thread-safe.
  struct Claim {
    std::uint64_t first = 0;
    std::size_t count = 0;
  };
  virtual Claim claim(std::size_t capacity) = 0;
  // Writes the claimed rays into `rays` and sets its count.
  virtual void fill_range(RayBatch& rays, const Claim& claimed) const = 0;
};

}  // namespace wavetrace
