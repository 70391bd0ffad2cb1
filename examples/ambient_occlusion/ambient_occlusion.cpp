// A chain of the library's stages and one written here: generate -> trace -> ambient
// occlusion -> film. The world (scene, accelerator, lights) comes from settings as
// `wavetrace render` builds it; the occlusion stage follows the public stage contract
// (<wavetrace/stages/stage.hpp>): it owns each batch it is given, reads the batch's hit
// columns, traces its own any-hit rays in a batch it acquires, and releases both.
// Usage: ambient_occlusion [SCENE] [--set section.key=value]... ; writes ambient_occlusion.pgm
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include <wavetrace/kernels/random.hpp>
#include <wavetrace/kernels/sampling.hpp>
#include <wavetrace/setup/render_setup.hpp>
#include <wavetrace/stages/stage.hpp>

namespace {

using namespace wavetrace;

// For each camera ray that hit: `rays_per_hit` cosine-distributed rays over the hit's
// hemisphere, `radius` long, and the share that escapes added to the pixel. Rays that
// missed see the open sky (1).
class AmbientOcclusionStage final : public Stage {
 public:
  AmbientOcclusionStage(const Accelerator& accelerator, Film& film, std::uint32_t rays_per_hit, float radius)
      : accelerator_(accelerator), film_(film), rays_per_hit_(rays_per_hit), radius_(radius) {}

  std::string name() const override { return "ambient_occlusion"; }

  void process(Batch* batch, StageOutput& out) const override {
    Batch* probes = out.acquire();
    const std::size_t per_batch = probes->rays.capacity() / rays_per_hit_;
    // The batch's rays in groups whose probe rays fill one probe batch.
    for (std::size_t first = 0; first < batch->rays.count; first += per_batch) {
      const std::size_t last = std::min(batch->rays.count, first + per_batch);
      RayBatch& rays = probes->rays;
      rays.count = 0;
      for (std::size_t i = first; i < last; ++i) {
        if (!batch->hits.is_hit(i)) continue;
        const glm::vec3 direction(batch->rays.direction_x[i], batch->rays.direction_y[i], batch->rays.direction_z[i]);
        glm::vec3 normal = glm::normalize(batch->hits.normal(i));
        if (glm::dot(normal, direction) > 0.0f) normal = -normal;  // the side the camera sees
        const glm::vec3 origin = batch->hits.point(i) + normal * (1e-4f * radius_);
        for (std::uint32_t k = 0; k < rays_per_hit_; ++k) {
          // The library's counter-based draws: the image repeats for any thread count.
          const UnitPair u = unit_pair(random_bits(batch->rays.pixel[i], batch->rays.sample[i], 1,
                                                   RandomPurpose::bounce_direction, k));
          const glm::vec3 probe = cosine_hemisphere(normal, u.first, u.second);
          const std::size_t slot = rays.count++;
          rays.set_geometry(slot, origin, probe, 0.0f, radius_);
          rays.pixel[slot] = batch->rays.pixel[i];
        }
      }
      accelerator_.intersect_any(rays, probes->hits, rays.all());
      for (std::size_t slot = 0; slot < rays.count; slot += rays_per_hit_) {
        std::uint32_t open = 0;
        for (std::uint32_t k = 0; k < rays_per_hit_; ++k) open += !probes->hits.is_hit(slot + k);
        const float ao = float(open) / float(rays_per_hit_);
        film_.add(rays.pixel[slot], ao, ao, ao);
      }
    }
    for (std::size_t i = 0; i < batch->rays.count; ++i) {
      if (!batch->hits.is_hit(i)) film_.add(batch->rays.pixel[i], 1.0f, 1.0f, 1.0f);
    }
    out.release(probes);
    out.release(batch);  // the camera rays end here
  }

 private:
  const Accelerator& accelerator_;
  Film& film_;
  std::uint32_t rays_per_hit_;
  float radius_;
};

}  // namespace

int main(int argc, char** argv) {
  try {
    Config config;
    config.set("render.width=320");
    config.set("render.height=240");
    config.set("render.spp=2");
    config.set("reorder.heuristic=none");  // no proxy: this chain has no approx_hit
    for (int a = 1; a < argc; ++a) {
      const std::string argument = argv[a];
      if (argument == "--set" && a + 1 < argc) {
        config.set(argv[++a]);
      } else {
        config.set("scene.source=" + argument);
      }
    }
    const RenderPlan plan = plan_render(config);
    const BuiltWorld built(plan);
    const World& world = built.world();
    const RenderPlan& done = built.plan();

    Film film(done.image.width, done.image.height);
    GenerateStage generate(built.camera(), done.image, done.pixel_order);
    const TraceStage trace(world.accelerator, world.scene.material_runs);
    const AmbientOcclusionStage occlusion(world.accelerator, film, 8, 0.25f * world.scene.bounds.diagonal());
    Pipeline pipeline(generate, {&trace, &occlusion}, /*loops=*/false, done.pipeline);
    const PipelineRun run = pipeline.run();

    const std::vector<float> image = film.resolve(done.image.samples_per_pixel);
    double sum = 0.0;
    std::ofstream pgm("ambient_occlusion.pgm", std::ios::binary);
    pgm << "P5\n" << done.image.width << " " << done.image.height << "\n255\n";
    for (std::size_t p = 0; p < image.size(); p += 3) {
      sum += image[p];
      pgm.put(char(std::lround(255.0f * std::clamp(image[p], 0.0f, 1.0f))));
    }
    std::printf("%s: %zu triangles, accelerator %s\n", world.scene.name.c_str(), world.scene.triangle_count,
                world.accelerator.name().c_str());
    for (const StageStats& stage : run.stages) {
      std::printf("  %-18s %10llu rays in %8.3f s  %7.2f Mrays/s per thread\n", stage.name.c_str(),
                  static_cast<unsigned long long>(stage.rays_in), stage.seconds, stage.mrays_per_s());
    }
    std::printf("mean ambient occlusion %.3f over %u x %u pixels; wrote ambient_occlusion.pgm\n",
                sum / double(image.size() / 3), done.image.width, done.image.height);
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "ambient_occlusion: error: %s\n", error.what());
    return 1;
  }
}
