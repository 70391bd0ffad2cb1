// One scene and accelerator, the path-traced reference, then a photon-mapped render per
// count and reach; every image is deterministic, so the table is too, but for its seconds.
#include "wavetrace/bench/photon_bench.hpp"

#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace {
namespace {

double mean_of(const std::vector<float>& image) {
  return std::accumulate(image.begin(), image.end(), 0.0) / double(std::max<std::size_t>(1, image.size()));
}

double rmse_between(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double difference = double(a[i]) - double(b[i]);
    sum += difference * difference;
  }
  return std::sqrt(sum / double(std::max<std::size_t>(1, a.size())));
}

}  // namespace

PhotonBenchReport run_photon_bench(const Config& config, const PhotonBenchRequest& request) {
  if (request.photon_counts.empty()) throw ConfigError("--photons names no photon count");
  if (request.reference_spp < 2) throw ConfigError("--reference-spp must be 2 or more (two halves measure its noise)");
  const RenderPlan plan = plan_render(config);
  const Scene scene = load_scene(plan.scene);
  const auto accelerator = build_world_accelerator(scene, plan.accelerator);
  const LightSampler lights = represented_lights(scene, *accelerator);
  std::unique_ptr<Proxy> proxy;
  if (plan.needs_proxy()) proxy = std::make_unique<Proxy>(scene.mesh, plan.proxy, *accelerator);
  const World world{scene, *accelerator, lights, proxy.get()};
  const Camera camera = resolve_camera(plan.camera, scene);

  PhotonBenchReport report;
  report.scene = scene.name;
  report.triangles = scene.triangle_count;
  report.image = fmt::format("{}x{}, {} spp, depth {}, {}", plan.image.width, plan.image.height,
                             plan.image.samples_per_pixel, plan.rules.max_depth, accelerator->name());
  report.reference_spp = request.reference_spp;

  // The reference's halves: seeds 2s and 2s + 1 of half the samples each are together the
  // samples of seed s at the full count.
  std::vector<float> halves[2];
  for (std::uint32_t half = 0; half < 2; ++half) {
    RenderPlan path = plan;
    path.integrator = Integrator::path;
    path.image.samples_per_pixel = request.reference_spp / 2;
    path.image.seed = 2 * plan.image.seed + half;
    const RenderOutput output = render_image(path, world, camera);
    report.reference_seconds += output.seconds();
    report.threads = output.run.threads;
    halves[half] = output.image;
  }
  std::vector<float> reference(halves[0].size());
  for (std::size_t i = 0; i < reference.size(); ++i) reference[i] = 0.5f * (halves[0][i] + halves[1][i]);
  report.reference_mean = mean_of(reference);
  report.reference_noise = 0.5 * rmse_between(halves[0], halves[1]);

  const std::vector<double> radii = request.radii.empty() ? std::vector<double>{plan.photon.radius} : request.radii;
  for (const std::uint64_t count : request.photon_counts) {
    for (const double radius : radii) {
      RenderPlan photon = plan;
      photon.integrator = Integrator::photon;
      photon.photon.count = count;
      photon.photon.radius = static_cast<float>(radius);
      const RenderOutput output = render_image(photon, world, camera);
      PhotonBenchResult result;
      result.photons = count;
      result.radius = output.photons->radius;
      result.global_photons = output.photons->global_photons;
      result.caustic_photons = output.photons->caustic_photons;
      result.seconds = output.seconds();
      result.photon_seconds = output.photons->run.seconds + output.photons->map_seconds;
      result.rmse = rmse_between(output.image, reference);
      result.relative_rmse = report.reference_mean > 0.0 ? result.rmse / report.reference_mean : 0.0;
      result.bias = report.reference_mean > 0.0 ? mean_of(output.image) / report.reference_mean - 1.0 : 0.0;
      report.results.push_back(result);
    }
  }
  return report;
}

nlohmann::json to_json(const PhotonBenchReport& report) {
  nlohmann::json results = nlohmann::json::array();
  for (const PhotonBenchResult& r : report.results) {
    results.push_back({{"photons", r.photons},
                       {"radius", r.radius},
                       {"global_photons", r.global_photons},
                       {"caustic_photons", r.caustic_photons},
                       {"seconds", r.seconds},
                       {"photon_seconds", r.photon_seconds},
                       {"rmse", r.rmse},
                       {"relative_rmse", r.relative_rmse},
                       {"bias", r.bias}});
  }
  return {{"scene", {{"source", report.scene}, {"triangles", report.triangles}}},
          {"image", report.image},
          {"threads", report.threads},
          {"reference",
           {{"spp", report.reference_spp},
            {"seconds", report.reference_seconds},
            {"mean", report.reference_mean},
            {"noise_rmse", report.reference_noise}}},
          {"results", results}};
}

std::string to_table(const PhotonBenchReport& report) {
  std::string table = fmt::format(
      "{}: {} triangles; {}; {} threads\nreference: path tracer at {} spp in {:.2f} s, mean {:.4f}, its own noise "
      "(RMSE) {:.4f} ({:.2f}% of the mean)\n",
      report.scene, report.triangles, report.image, report.threads, report.reference_spp, report.reference_seconds,
      report.reference_mean, report.reference_noise, 100.0 * report.reference_noise / std::max(report.reference_mean, 1e-30));
  table += fmt::format("{:>10} {:>9} {:>10} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8}\n", "photons", "radius", "landed",
                       "caustic", "seconds", "photon s", "RMSE", "rel RMSE", "bias");
  for (const PhotonBenchResult& r : report.results) {
    table += fmt::format("{:>10} {:>9.4g} {:>10} {:>9} {:>9.3f} {:>9.3f} {:>9.4f} {:>8.2f}% {:>7.2f}%\n", r.photons,
                         r.radius, r.global_photons, r.caustic_photons, r.seconds, r.photon_seconds, r.rmse,
                         100.0 * r.relative_rmse, 100.0 * r.bias);
  }
  table += "RMSE and bias against the reference; bias: the render's mean over the reference's, less 1\n";
  return table;
}

}  // namespace wavetrace
