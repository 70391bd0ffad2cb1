// Photon emission: a light sample, a cosine-weighted direction, flux Le pi / (pdf_area N).
#include "wavetrace/stages/emit_photons.hpp"

#include <limits>
#include <stdexcept>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/ray_offset.hpp"
#include "wavetrace/kernels/sampling.hpp"
#include "wavetrace/stages/photon_rules.hpp"

namespace wavetrace {

EmitPhotonsStage::EmitPhotonsStage(const LightSampler& lights, std::uint64_t count, std::uint32_t seed)
    : lights_(lights), count_(lights.empty() ? 0 : count), sample_(photon_sample(seed)) {
  if (count > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("photon.count: at most 2^32 - 1 photons (each is keyed by a 32-bit index)");
  }
}

RaySource::Claim EmitPhotonsStage::claim(std::size_t capacity) {
  const std::uint64_t first = next_.fetch_add(capacity, std::memory_order_relaxed);
  if (first >= count_) return {};
  return {first, static_cast<std::size_t>(std::min<std::uint64_t>(capacity, count_ - first))};
}

void EmitPhotonsStage::fill_range(RayBatch& rays, const Claim& claimed) const {
  // Leaving a point of density pdf_area along cos / pi, a photon stands for
  // Le cos / (pdf_area (cos / pi)) of flux, shared among count_ photons.
  const float share = kPi / float(count_);
  for (std::size_t slot = 0; slot < claimed.count; ++slot) {
    const auto photon = static_cast<std::uint32_t>(claimed.first + slot);
    const std::uint64_t key = path_key(photon, sample_);
    const LightSample light =
        lights_.sample(unit_float32(path_draw(key, 0, RandomPurpose::light_choice)),
                       unit_float32(path_draw(key, 0, RandomPurpose::light_point, 0)),
                       unit_float32(path_draw(key, 0, RandomPurpose::light_point, 1)));
    const glm::vec3 direction =
        cosine_hemisphere(light.normal, unit_float32(path_draw(key, 0, RandomPurpose::photon_emission, 0)),
                          unit_float32(path_draw(key, 0, RandomPurpose::photon_emission, 1)));
    const glm::vec3 power = light.emission * (share / light.pdf_area);
    rays.set_geometry(slot, offset_ray_origin(light.point, light.normal), direction, 0.0f,
                      std::numeric_limits<float>::infinity());
    rays.pixel[slot] = photon;
    rays.sample[slot] = sample_;
    rays.depth[slot] = 0;
    rays.kind[slot] = RayKind::bounce;
    rays.throughput_r[slot] = power.r;
    rays.throughput_g[slot] = power.g;
    rays.throughput_b[slot] = power.b;
    rays.flags[slot] = ray_flags::alive;
  }
  rays.count = claimed.count;
}

}  // namespace wavetrace
