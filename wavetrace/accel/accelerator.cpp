// The accelerator interface's vtable anchor and the defaults of its probed queries.
#include "wavetrace/accel/accelerator.hpp"

#include <stdexcept>

namespace wavetrace {

void Accelerator::intersect_closest_probed(const RayBatch&, HitBatch&, RayRange, RecordingProbe&) const {
  throw std::logic_error("accelerator '" + name() + "' cannot report its memory reads");
}

void Accelerator::intersect_any_probed(const RayBatch&, HitBatch&, RayRange, RecordingProbe&) const {
  throw std::logic_error("accelerator '" + name() + "' cannot report its memory reads");
}

void Accelerator::save(SectionWriter&, const std::string&) const {
  throw std::logic_error("accelerator '" + name() + "' cannot be saved");
}

}  // namespace wavetrace
