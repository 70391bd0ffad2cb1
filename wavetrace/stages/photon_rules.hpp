// The photon mapping integrator's settings (render.integrator, photon.*), shared by its
// stages and the render that runs its two passes.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace wavetrace {

// path: the path tracer. photon: a photon pass fills the photon maps, then camera rays take
// direct light by shadow rays, caustics from the caustic map, and the rest by final gathering
// from the global map (Jensen's method; the reordering paper's second integrator, §5.2).
enum class Integrator { path, photon };
inline Integrator parse_integrator(const std::string& text) {
  if (text == "path") return Integrator::path;
  if (text == "photon") return Integrator::photon;
  throw std::invalid_argument("unknown integrator '" + text + "' (path, photon)");
}

struct PhotonOptions {
  std::uint64_t count = 1000000;   // photons emitted from the lights
  std::uint32_t k = 100;           // photons an irradiance estimate gathers
  float radius = 0.0f;             // the farthest an estimate reaches; 0: 0.25% of the scene's diagonal
  std::uint32_t gather_rays = 10;  // final-gathering rays from each diffuse hit of a camera path
  // Irradiance precomputed at every this many photons of the global map, read by gathering
  // rays at the nearest (Christensen 1999); 0: the full estimate at every gathering hit.
  std::uint32_t precompute = 0;
  bool operator==(const PhotonOptions&) const = default;
};

// The sample number photon paths are keyed with (with their emission index as the pixel):
// far above any camera sample's, so photon and camera draws never share a key.
inline std::uint32_t photon_sample(std::uint32_t seed) { return ~seed; }

}  // namespace wavetrace
