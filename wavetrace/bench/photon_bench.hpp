// `wavetrace bench photons`: photon mapping against the path tracer on one image. The
// reference is the path tracer at many samples, rendered as two halves of independent
// samples so that its own noise is measured (half their RMSE); then each photon count (and
// reach) renders the image by photon mapping, with its seconds, its RMSE against the
// reference and its bias (how far its mean is from the reference's), so the error can be
// charted against the time as photons grow.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "wavetrace/setup/config.hpp"

namespace wavetrace {

struct PhotonBenchRequest {
  std::uint32_t reference_spp = 4096;
  std::vector<std::uint64_t> photon_counts = {10000, 100000, 1000000};
  std::vector<double> radii;  // photon.radius values to try at each count; empty: the config's
};

struct PhotonBenchResult {
  std::uint64_t photons = 0;
  double radius = 0.0;  // as resolved
  std::size_t global_photons = 0, caustic_photons = 0;
  double seconds = 0.0;         // the whole render
  double photon_seconds = 0.0;  // its photon pass and maps
  double rmse = 0.0;            // linear RGB, every pixel and channel, against the reference
  double relative_rmse = 0.0;   // over the reference's mean
  double bias = 0.0;            // mean over the reference's mean, less 1
};

struct PhotonBenchReport {
  std::string scene;
  std::size_t triangles = 0;
  std::string image;
  int threads = 0;
  std::uint32_t reference_spp = 0;
  double reference_seconds = 0.0;
  double reference_mean = 0.0;
  double reference_noise = 0.0;  // the reference's own RMSE, from its two halves
  std::vector<PhotonBenchResult> results;
};

// `config` holds the scene and render settings (render.spp is the photon renders'); throws
// ConfigError for an empty list of counts or a reference_spp under 2.
PhotonBenchReport run_photon_bench(const Config& config, const PhotonBenchRequest& request);

nlohmann::json to_json(const PhotonBenchReport& report);
std::string to_table(const PhotonBenchReport& report);

}  // namespace wavetrace
