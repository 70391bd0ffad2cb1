// approx_hit (the reordering paper, §4.2): each ray's hit point on the proxy, or its
// virtual hit point on the scene's box when it misses the proxy but not the box, written
// to the approximate-hit column for zsort. A ray that misses the box cannot hit the scene:
// its sky or light goes to the film here and it leaves the chain, counted (never traced).
// Approximate hits order rays; they never shade.
#pragma once

#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/memory/memory_probe.hpp"
#include "wavetrace/stages/film.hpp"
#include "wavetrace/stages/hit_rates.hpp"
#include "wavetrace/stages/stage.hpp"

namespace wavetrace {

class ApproxHitStage final : public Stage {
 public:
  // `film` null: rays that leave carry light to no pixel (the photon pass's). `hit_rates`
  // (optional) counts box misses of camera and bounce rays as misses, so the per-depth hit
  // rates do not depend on the chain. `observers` (optional) see the proxy's reads.
  ApproxHitStage(const Proxy& proxy, Film* film, const glm::vec3& background, HitRateCounters* hit_rates = nullptr,
                 const MemoryObservers* observers = nullptr);
  std::string name() const override { return "approx_hit"; }
  void process(Batch* batch, StageOutput& out) const override;

 private:
  const Proxy& proxy_;
  Film* film_;
  glm::vec3 background_;
  HitRateCounters* hit_rates_;
  const MemoryObservers* observers_;
};

}  // namespace wavetrace
