// Perfect reflection and a smooth dielectric's reflection or refraction (Fresnel's equations),
// shared by the path tracer and the photon tracer so both bend light the same way.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace wavetrace {

// `incoming` mirrored about the plane of unit `normal` (either side).
inline glm::vec3 reflect_direction(const glm::vec3& incoming, const glm::vec3& normal) {
  return incoming - normal * (2.0f * glm::dot(incoming, normal));
}

// Unpolarized Fresnel reflectance of a dielectric interface, for light arriving at cosine
// `cos_incident` (> 0) with eta = n_incident / n_transmitted and the refracted cosine
// `cos_transmitted` (Snell's law): the mean of the s and p amplitudes squared.
inline float dielectric_reflectance(float cos_incident, float cos_transmitted, float eta) {
  const float s = (eta * cos_incident - cos_transmitted) / (eta * cos_incident + cos_transmitted);
  const float p = (cos_incident - eta * cos_transmitted) / (cos_incident + eta * cos_transmitted);
  return 0.5f * (s * s + p * p);
}

struct SpecularScatter {
  glm::vec3 direction;  // unit
  bool transmitted;     // crossed the surface: the new origin goes to its far side
};

// Where light arriving along unit `incoming` goes at glass of index `ior` whose unit
// `outward` normal points to the side of index 1: reflected with Fresnel's probability
// (always, past the critical angle), else refracted; `u` in [0, 1) chooses. Choosing by the
// reflectance makes the path's weight the glass's tint whichever way it goes. Radiance is
// not scaled by eta^2 at each crossing: for closed glass objects (nothing emits or scatters
// inside them) the factors of entering and leaving cancel.
inline SpecularScatter glass_scatter(const glm::vec3& incoming, const glm::vec3& outward, float ior, float u) {
  float cos_incident = -glm::dot(incoming, outward);
  glm::vec3 facing = outward;  // the normal on the incoming light's side
  float eta = 1.0f / ior;      // entering
  if (cos_incident < 0.0f) {   // leaving, from inside
    cos_incident = -cos_incident;
    facing = -outward;
    eta = ior;
  }
  const float sin2_transmitted = eta * eta * std::max(0.0f, 1.0f - cos_incident * cos_incident);
  if (sin2_transmitted >= 1.0f) return {reflect_direction(incoming, facing), false};  // total internal reflection
  const float cos_transmitted = std::sqrt(1.0f - sin2_transmitted);
  if (u < dielectric_reflectance(cos_incident, cos_transmitted, eta)) return {reflect_direction(incoming, facing), false};
  const glm::vec3 refracted = incoming * eta + facing * (eta * cos_incident - cos_transmitted);
  return {glm::normalize(refracted), true};
}

}  // namespace wavetrace
