// Rendering through the pipeline: exact answers where the physics gives one, and
// bit-identical images across thread counts, batch sizes, pixel orders, films and modes.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>
#include <tbb/info.h>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/stages/buffering_stage.hpp"

namespace wavetrace {
namespace {

struct Rendered {
  RenderOutput output;
  RenderPlan plan;
};

Rendered render(const Scene& scene, const std::vector<std::string>& settings) {
  Config config;
  config.set("render.width=48");
  config.set("render.height=36");
  config.set("render.spp=2");
  for (const std::string& setting : settings) config.set(setting);
  Rendered result;
  result.plan = plan_render(config);
  const auto accelerator = make_accelerator(scene.mesh, result.plan.accelerator);
  const LightSampler lights(scene);
  const World world{scene, *accelerator, lights};
  result.output = render_image(result.plan, world, resolve_camera(result.plan.camera, scene));
  return result;
}

const Scene& default_scene() {
  static const Scene scene = make_builtin_scene("builtin:default:5000");
  return scene;
}

TEST(Render, ImageIsIdenticalForThreadsBatchSizesPixelOrdersFilmsAndModes) {
  const Rendered reference = render(default_scene(), {"render.threads=1", "render.batch_size=4096"});
  const std::vector<std::vector<std::string>> variants = {
      {"render.threads=2", "render.batch_size=4096"},
      {"render.threads=2", "render.batch_size=64"},
      {"render.threads=1", "render.batch_size=17", "render.pixel_order=scanline"},
      {"render.threads=2", "render.batch_size=1000", "render.rays_in_flight=2048"},
      {"render.threads=2", "render.film=per_thread"},
      {"render.threads=2", "render.film=per_thread", "pipeline.mode=megakernel"},
  };
  double sum = 0.0;
  for (float value : reference.output.image) sum += value;
  EXPECT_GT(sum, 0.0);
  for (const auto& variant : variants) {
    const Rendered other = render(default_scene(), variant);
    ASSERT_EQ(other.output.image.size(), reference.output.image.size());
    EXPECT_TRUE(other.output.image == reference.output.image) << "differs with " << variant[0] << " " << variant[1];
  }
}

// Generate runs on several threads at once: every camera ray is claimed exactly once, and a
// claimed batch holds the rays fill would have made in order.
TEST(Generate, ClaimsEveryRayOnceFromManyThreads) {
  const ImageSpec image{.width = 37, .height = 11, .samples_per_pixel = 3};
  GenerateStage generate(resolve_camera({}, default_scene()), image, PixelOrder::zcurve);
  std::vector<std::atomic<int>> claimed(generate.total_rays());
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      RayBatch rays(7);
      for (GenerateStage::Claim claim = generate.claim(7); claim.count > 0; claim = generate.claim(7)) {
        generate.fill_range(rays, claim);
        ASSERT_EQ(rays.count, claim.count);
        for (std::size_t i = 0; i < claim.count; ++i) {
          ++claimed[claim.first + i];
          EXPECT_EQ(rays.sample[i], (claim.first + i) % 3);
        }
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_TRUE(generate.exhausted());
  EXPECT_EQ(generate.generated(), generate.total_rays());
  for (std::size_t i = 0; i < claimed.size(); ++i) ASSERT_EQ(claimed[i].load(), 1) << i;
}

// Passes of one render share a batch pool (photon mapping's two): a pipeline given a pool
// takes its batches from it, so a second run of the same work allocates none, and a pool
// of another batch size is refused.
TEST(Render, PipelinesSharingABatchPoolReuseItsBatches) {
  class ReleasingStage final : public Stage {
   public:
    std::string name() const override { return "release"; }
    void process(Batch* batch, StageOutput& out) const override { out.release(batch); }
  };
  const ImageSpec image{.width = 64, .height = 64, .samples_per_pixel = 4};
  const ReleasingStage release;
  PipelineOptions options;
  options.batch_size = 256;
  options.threads = 1;
  BatchPool pool(options.batch_size);
  GenerateStage first_generate(resolve_camera({}, default_scene()), image, PixelOrder::scanline);
  Pipeline first(first_generate, {&release}, false, options, &pool);
  first.run();
  const std::size_t allocated = pool.allocated();
  EXPECT_GT(allocated, 0u);
  GenerateStage second_generate(resolve_camera({}, default_scene()), image, PixelOrder::scanline);
  Pipeline second(second_generate, {&release}, false, options, &pool);
  const PipelineRun run = second.run();
  EXPECT_EQ(pool.allocated(), allocated);
  EXPECT_EQ(run.stages.at(1).rays_in, std::size_t(image.width) * image.height * image.samples_per_pixel);

  BatchPool other_size(options.batch_size * 2);
  GenerateStage third_generate(resolve_camera({}, default_scene()), image, PixelOrder::scanline);
  Pipeline third(third_generate, {&release}, false, options, &other_size);
  EXPECT_THROW(third.run(), std::logic_error);
}

// Holds every batch until it holds every live ray, then emits them in arrival order,
// noting each batch's place in the flush. Its count is sequentially consistent, as zsort's:
// the pipeline's node reads the live rays after writing it while a retiring thread reads it
// after changing them, and one of the two must see the other's write to make it flush.
class HoldingStage final : public BufferingStage {
 public:
  std::string name() const override { return "hold"; }
  void process(Batch* batch, StageOutput& out) const override { take(batch, out); }
  std::size_t take(Batch* batch, StageOutput&) const override {
    held_.push_back(batch);
    rays_.store(rays_.load() + batch->rays.count);  // only the serial node writes it
    return 0;
  }
  std::size_t flush(StageOutput& out) const override {
    for (Batch* batch : held_) {
      {
        std::lock_guard lock(place_mutex_);  // the next stage reads places while this one writes
        place_[batch] = place_.size();
      }
      out.emit(batch);
    }
    held_.clear();
    return rays_.exchange(0);
  }
  std::size_t buffered_rays() const override { return rays_.load(); }
  std::size_t place(Batch* batch) const {
    std::lock_guard lock(place_mutex_);
    return place_.at(batch);
  }

 private:
  mutable std::vector<Batch*> held_;
  mutable std::mutex place_mutex_;
  mutable std::map<Batch*, std::size_t> place_;
  mutable std::atomic<std::size_t> rays_{0};
};

// The flight budget bounds the rays alive, not only the camera rays: a stage that makes eight
// rays of each (as a gather makes its rays) has the generator leave room for them. A stage
// after it holds every ray until it holds all that are alive, so what was made piles up.
TEST(Render, TheFlightBudgetBoundsWhatCameraRaysBecome) {
  constexpr std::size_t kRaysPerRay = 8;
  class FanOutStage final : public Stage {
   public:
    std::string name() const override { return "fan_out"; }
    std::size_t rays_out_per_ray() const override { return kRaysPerRay; }
    void process(Batch* batch, StageOutput& out) const override {
      for (std::size_t copy = 0; copy < kRaysPerRay; ++copy) {
        Batch* made = out.acquire();
        for (std::size_t i = 0; i < batch->rays.count; ++i) made->rays.copy_ray(i, batch->rays, i);
        made->rays.count = batch->rays.count;
        out.emit(made);
      }
      out.release(batch);
    }
  };
  const ImageSpec image{.width = 64, .height = 64, .samples_per_pixel = 4};
  const FanOutStage fan_out;
  const HoldingStage hold;
  PipelineOptions options;
  options.batch_size = 256;
  options.threads = 2;
  options.rays_in_flight = 16384;
  GenerateStage generate(resolve_camera({}, default_scene()), image, PixelOrder::scanline);
  const PipelineRun run = Pipeline(generate, {&fan_out, &hold}, false, options).run();
  EXPECT_EQ(run.stages.at(2).rays_in, kRaysPerRay * image.width * image.height * image.samples_per_pixel);
  // Each thread generating at once may take one batch past the room left, and each becomes
  // kRaysPerRay batches. (Undeclared, the fan-out left 116,992 rays alive at once.)
  EXPECT_LE(run.peak_rays_in_core, options.rays_in_flight + std::size_t(options.threads) * options.batch_size * kRaysPerRay);
  EXPECT_GE(run.peak_rays_in_core, options.batch_size * kRaysPerRay);  // what a camera batch became is counted
}

// An error inside a stage while progress is being reported reaches the caller as that
// error (the reporting thread is stopped and joined on the way out, not left to terminate).
TEST(Render, AStageErrorDuringProgressReportsReachesTheCaller) {
  class FailingStage final : public Stage {
   public:
    std::string name() const override { return "failing"; }
    void process(Batch* batch, StageOutput& out) const override {
      if (seen_.fetch_add(1) == 3) throw std::runtime_error("the fourth batch fails");
      out.release(batch);
    }

   private:
    mutable std::atomic<int> seen_{0};
  };
  const ImageSpec image{.width = 64, .height = 64, .samples_per_pixel = 4};
  GenerateStage generate(resolve_camera({}, default_scene()), image, PixelOrder::scanline);
  const FailingStage failing;
  PipelineOptions options;
  options.batch_size = 256;
  options.threads = 2;
  Pipeline pipeline(generate, {&failing}, false, options);
  try {
    pipeline.run([](const Progress&) {}, std::chrono::milliseconds(1));
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "the fourth batch fails");
  }
}

// A buffering stage's flush reaches the next stage in its order, on any number of threads:
// each batch starts within a few places of its place in the flush (without the pipeline's
// ordered gate, the emitting thread would take the last batches first while the other took
// the first ones: the threads would walk a sorted stream from both ends).
TEST(Render, BatchesLeaveABufferingStageInTheirOrder) {
  class RecordingStage final : public Stage {
   public:
    explicit RecordingStage(const HoldingStage& hold) : hold_(hold) {}
    std::string name() const override { return "record"; }
    void process(Batch* batch, StageOutput& out) const override {
      {
        const std::lock_guard lock(mutex_);
        started.push_back(hold_.place(batch));
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));  // long enough for the threads to overlap
      out.release(batch);
    }
    mutable std::vector<std::size_t> started;

   private:
    const HoldingStage& hold_;
    mutable std::mutex mutex_;
  };
  for (int asked : {1, 2, 4}) {
    // Only as many threads as cores: past them a thread can be descheduled between taking a
    // batch and recording it for as long as the OS likes (4 threads on 2 cores under the
    // sanitizers: a batch recorded 13 places late), which says nothing of the hand-off's order.
    const int threads = std::min(asked, tbb::info::default_concurrency());
    const ImageSpec image{.width = 64, .height = 64, .samples_per_pixel = 4};
    GenerateStage generate(resolve_camera({}, default_scene()), image, PixelOrder::scanline);
    const HoldingStage hold;
    const RecordingStage record(hold);
    PipelineOptions options;
    options.batch_size = 256;
    options.threads = threads;
    options.rays_in_flight = 1 << 20;  // every batch held before the flush
    Pipeline(generate, {&hold, &record}, false, options).run();
    ASSERT_EQ(record.started.size(), 64u);
    for (std::size_t position = 0; position < record.started.size(); ++position) {
      const auto distance = std::max(record.started[position], position) - std::min(record.started[position], position);
      EXPECT_LE(distance, std::size_t(2 * threads)) << threads << " threads: batch " << record.started[position]
                                                    << " of the flush started " << position << "th";
    }
  }
}

// The look-ahead sees the queued batches in their order, never more than `depth` past the
// next one taken, never one already taken; closing the hand-off ends its wait.
TEST(Render, AHandOffsLookAheadSeesQueuedBatchesInOrderWithinItsDepth) {
  BatchPool pool(4);
  std::vector<Batch*> batches;
  for (int i = 0; i < 5; ++i) {
    batches.push_back(pool.acquire());
    batches.back()->rays.count = std::size_t(i);  // names the batch
  }
  OrderedHandOff hand_off;
  std::vector<std::size_t> seen;
  const auto note = [&](const Batch& batch) { seen.push_back(batch.rays.count); };
  for (Batch* batch : batches) hand_off.push(batch);
  ASSERT_TRUE(hand_off.next_ahead(2, note));
  ASSERT_TRUE(hand_off.next_ahead(2, note));
  EXPECT_EQ(seen, (std::vector<std::size_t>{0, 1}));
  std::atomic<bool> third_seen{false};
  std::thread reader([&] {
    if (hand_off.next_ahead(2, note)) third_seen = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(third_seen.load());  // batch 2 is two places past the next one taken
  EXPECT_EQ(hand_off.pop()->rays.count, 0u);
  reader.join();
  EXPECT_TRUE(third_seen.load());
  EXPECT_EQ(seen.back(), 2u);
  for (std::size_t expected : {1, 2, 3}) EXPECT_EQ(hand_off.pop()->rays.count, expected);
  ASSERT_TRUE(hand_off.next_ahead(2, note));  // batch 3 was taken unseen: the next is 4
  EXPECT_EQ(seen.back(), 4u);
  std::thread waiting([&] { EXPECT_FALSE(hand_off.next_ahead(2, note)); });
  hand_off.close();
  waiting.join();
  EXPECT_EQ(hand_off.pop()->rays.count, 4u);
  for (Batch* batch : batches) pool.release(batch);
}

TEST(Render, ConvexObjectUnderUniformSkyReflectsItsAlbedoExactly) {
  // Every bounce from a convex surface escapes to the sky, so each sample of the object
  // returns exactly albedo x sky: no noise, an exact expected value.
  Scene scene;
  scene.name = "octahedron";
  scene.mesh.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (std::uint32_t x : {0u, 1u}) {
    for (std::uint32_t y : {2u, 3u}) {
      for (std::uint32_t z : {4u, 5u}) {
        // Wind each face outward: flip when the axes' signs make an odd permutation.
        const bool flip = (x == 1) ^ (y == 3) ^ (z == 5);
        scene.mesh.triangles.push_back(flip ? glm::uvec3(x, z, y) : glm::uvec3(x, y, z));
      }
    }
  }
  validate_and_clean(scene.mesh, "octahedron");
  scene.materials = {Material{glm::vec3(0.25f, 0.5f, 0.75f)}};
  scene.background = glm::vec3(2.0f);
  scene.camera = Camera{glm::vec3(0, 0, 6), glm::vec3(0), glm::vec3(0, 1, 0), 30.0f};
  const Rendered result = render(scene, {"render.max_depth=1", "render.spp=3"});
  const std::vector<float>& image = result.output.image;
  const auto pixel = [&](std::uint32_t x, std::uint32_t y, int c) { return image[(y * 48 + x) * 3 + c]; };
  EXPECT_NEAR(pixel(24, 18, 0), 0.5f, 1e-5f);  // centre: on the object
  EXPECT_NEAR(pixel(24, 18, 1), 1.0f, 1e-5f);
  EXPECT_NEAR(pixel(24, 18, 2), 1.5f, 1e-5f);
  EXPECT_NEAR(pixel(0, 0, 0), 2.0f, 1e-5f);  // corner: sky
}

TEST(Render, StageCountsAddUp) {
  const Rendered result = render(default_scene(), {});
  const auto& stages = result.output.run.stages;
  ASSERT_EQ(stages.size(), 4u);
  EXPECT_EQ(stages[0].name, "generate");
  EXPECT_EQ(stages[0].rays_out, 48u * 36 * 2);
  EXPECT_EQ(stages[1].name, "trace");
  // Everything traced came from generate or spawn.
  EXPECT_EQ(stages[1].rays_in, stages[0].rays_out + stages[3].rays_out);
  EXPECT_EQ(stages[2].rays_in, stages[1].rays_out);
  EXPECT_EQ(stages[3].rays_in, stages[2].rays_out);
  EXPECT_GT(stages[3].rays_out, 0u);
  EXPECT_EQ(result.output.rejected_contributions, 0u);
}

TEST(Render, ChainWithoutSpawnStopsAfterOneSegment) {
  const Rendered result = render(default_scene(), {"pipeline.stages=generate,trace,shade"});
  const auto& stages = result.output.run.stages;
  ASSERT_EQ(stages.size(), 3u);
  EXPECT_EQ(stages[1].rays_in, 48u * 36 * 2);
}

TEST(Render, MaxDepthZeroIsDirectLightOnly) {
  const Rendered direct = render(default_scene(), {"render.max_depth=0"});
  const Rendered full = render(default_scene(), {"render.max_depth=5"});
  double direct_sum = 0.0, full_sum = 0.0;
  for (float v : direct.output.image) direct_sum += v;
  for (float v : full.output.image) full_sum += v;
  EXPECT_GT(direct_sum, 0.0);
  EXPECT_GT(full_sum, direct_sum);  // indirect light adds energy
  // Without bounces, spawn makes shadow rays only: as many as trace saw camera hits at most.
  EXPECT_LE(direct.output.run.stages[3].rays_out, direct.output.run.stages[0].rays_out);
}

TEST(Render, BvhAndEmbreeRenderTheSameImage) {
  const Rendered embree = render(default_scene(), {"accel.type=embree"});
  const Rendered bvh = render(default_scene(), {"accel.type=bvh", "accel.bvh.layout=veb"});
  double embree_sum = 0.0, difference = 0.0;
  for (std::size_t i = 0; i < embree.output.image.size(); ++i) {
    embree_sum += embree.output.image[i];
    difference += std::fabs(embree.output.image[i] - bvh.output.image[i]);
  }
  // Same rays, same randomness: only rays through shared edges may pick the other triangle.
  EXPECT_LT(difference, 1e-3 * embree_sum);
}

}  // namespace
}  // namespace wavetrace
