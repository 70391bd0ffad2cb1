// `wavetrace bench image`: the same image rendered with each accelerator, every image
// compared with the first's (the reference): a lossy accelerator's speed next to what its
// loss does to the picture.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/setup/config.hpp"

namespace wavetrace {

struct ImageBenchResult {
  std::string label;
  double bytes_per_triangle = 0.0;
  double build_seconds = 0.0;
  double render_seconds = 0.0;
  double closest_mrays_per_s = 0.0;  // camera and bounce rays per trace thread-second
  double rmse = 0.0;                 // linear RGB, all pixels and channels, against the first image
  double relative_rmse = 0.0;        // rmse over the first image's mean channel value
  double max_difference = 0.0;       // largest channel difference
  std::string notes;                 // the accelerator's build notes
  bool noise_floor = false;          // the reference with other samples: its rmse is Monte Carlo noise
};

struct ImageBenchReport {
  std::string scene;
  std::size_t triangles = 0;
  std::string image;  // WxH, spp, depth
  int threads = 0;
  std::vector<ImageBenchResult> results;
};

// `config` holds the scene, camera and render settings; the first accelerator's image is
// the reference. With `noise_floor`, the reference is rendered again with render.seed + 1:
// the difference no accelerator can be told from. Throws ConfigError for an empty list.
ImageBenchReport run_image_bench(const Config& config, std::vector<AcceleratorSpec> accelerators,
                                 bool noise_floor = false);

nlohmann::json to_json(const ImageBenchReport& report);
std::string to_table(const ImageBenchReport& report);

}  // namespace wavetrace
