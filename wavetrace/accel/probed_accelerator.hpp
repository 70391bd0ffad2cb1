// The query entry points of an accelerator whose traversal is one template over the probe
// type: the plain queries instantiate it with NullProbe (no cost), the probed ones with
// RecordingProbe. Static dispatch only; no virtual call per ray.
#pragma once

#include "wavetrace/accel/accelerator.hpp"

namespace wavetrace {

// Derived provides: template <bool kAnyHit, typename Probe>
//   void traverse(const RayBatch&, HitBatch&, RayRange, Probe&) const;
template <typename Derived>
class ProbedAccelerator : public Accelerator {
 public:
  void intersect_closest(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    NullProbe probe;
    self().template traverse<false>(rays, hits, range, probe);
  }
  void intersect_any(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    NullProbe probe;
    self().template traverse<true>(rays, hits, range, probe);
  }
  bool probed() const override { return true; }
  void intersect_closest_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                                RecordingProbe& probe) const override {
    self().template traverse<false>(rays, hits, range, probe);
  }
  void intersect_any_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                            RecordingProbe& probe) const override {
    self().template traverse<true>(rays, hits, range, probe);
  }

 private:
  const Derived& self() const { return static_cast<const Derived&>(*this); }
};

}  // namespace wavetrace
