// The megakernel: the path tracer run one path at a time, camera ray to last bounce, in
// one loop per worker (TBB over pixel tiles). It is the control experiment for the
// wavefront, so it calls the very stage functions the wavefront's nodes call, on one ray,
// and with the same random numbers its image is bit-identical to the wavefront's.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>

#include "wavetrace/stages/generate.hpp"
#include "wavetrace/pipeline/pipeline.hpp"
#include "wavetrace/pipeline/progress_reporter.hpp"
#include "wavetrace/stages/shade.hpp"
#include "wavetrace/stages/spawn.hpp"
#include "wavetrace/stages/trace.hpp"

namespace wavetrace {

struct MegakernelOptions {
  int threads = 0;               // 0: all cores
  std::uint32_t tile_side = 16;  // pixels per side of the square tiles workers take
};

// Renders every (pixel, sample) of `generate`'s image. Without `spawn`, paths end at their
// first hit (as a chain without spawn does). The run's one stage, "megakernel", counts the
// rays traced (camera, bounce and shadow) and the workers' busy thread-seconds.
PipelineRun run_megakernel(const GenerateStage& generate, const TraceStage& trace, const ShadeStage& shade,
                           const SpawnStage* spawn, const MegakernelOptions& options,
                           const std::function<void(const Progress&)>& on_progress = {},
                           std::chrono::milliseconds interval = std::chrono::milliseconds(250));

}  // namespace wavetrace
