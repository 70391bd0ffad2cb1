// The query entry points of an accelerator whose traversal is one template over the probe
// type and the kernel set: the plain queries instantiate it with NullProbe (no cost) for the
// set chosen at start (memory/kernel_isa_choice.hpp), the probed ones with RecordingProbe. Static
// dispatch only; no virtual call per ray, one branch per batch range.
#pragma once

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"

namespace wavetrace {

// Derived provides: template <bool kAnyHit, KernelIsa kIsa, typename Probe>
//   void traverse(const RayBatch&, HitBatch&, RayRange, Probe&) const;
// kIsa lets a walk take an AVX-512 path of its own; the whole walk is compiled for the set
// either way.
template <typename Derived>
class ProbedAccelerator : public Accelerator {
 public:
  void intersect_closest(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    walk_with(isa_, [&]<KernelIsa kIsa>() {
      NullProbe probe;
      self().template traverse<false, kIsa>(rays, hits, range, probe);
    });
  }
  void intersect_any(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    walk_with(isa_, [&]<KernelIsa kIsa>() {
      NullProbe probe;
      self().template traverse<true, kIsa>(rays, hits, range, probe);
    });
  }
  bool probed() const override { return true; }
  // Probed walks run the same set as the plain ones: they are what a paged render traces
  // with (the probe keeps the real pager's LRU order), so they must be as fast.
  void intersect_closest_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                                RecordingProbe& probe) const override {
    walk_with(isa_, [&]<KernelIsa kIsa>() { self().template traverse<false, kIsa>(rays, hits, range, probe); });
  }
  void intersect_any_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                            RecordingProbe& probe) const override {
    walk_with(isa_, [&]<KernelIsa kIsa>() { self().template traverse<true, kIsa>(rays, hits, range, probe); });
  }

  std::string isa() const override { return std::string(to_string(isa_)); }
  void use_isa(KernelIsa isa) override { isa_ = isa; }

 protected:
  KernelIsa kernel_isa() const { return isa_; }

 private:
  const Derived& self() const { return static_cast<const Derived&>(*this); }

  KernelIsa isa_ = default_kernel_isa();
};

}  // namespace wavetrace
