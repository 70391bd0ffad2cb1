// A render shared by ranks: every rank renders the camera rays rank 0 deals out on demand and
// the films' fixed-point sums are added on rank 0, so its image is bit for bit the one a
// single process renders. distribute.mode = image: every rank holds the whole world; data:
// a ChunkExchange routes the rays due at chunks a rank does not own to their owners.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "wavetrace/distribute/chunk_exchange.hpp"
#include "wavetrace/distribute/mpi_session.hpp"
#include "wavetrace/memory/process_cpu.hpp"
#include "wavetrace/setup/render_image.hpp"

namespace wavetrace {

// What one rank did, as rank 0 gathers it.
struct RankReport {
  int rank = 0;
  std::string host;
  std::uint64_t ranges = 0;       // ray ranges it was dealt
  std::uint64_t camera_rays = 0;  // camera rays it generated
  std::uint64_t rays_traced = 0;  // rays its trace stage took (camera, bounce, shadow)
  double render_seconds = 0.0;    // its render, from the common start to its last ray
  // Its process's CPU, every thread, from the common start until every rank was done: in data
  // mode the rays it answered for others after its own were done count too.
  ProcessCpuTime cpu;
  double wait_seconds = 0.0;      // waiting for ranges from rank 0
  std::uint64_t peak_resident_bytes = 0;  // VmHWM after its render (data mode: since the load, see below)
  // Data mode: VmHWM at the end of the load, whose checks read every chunk; its world's pages
  // are then given back and the peak window restarted, so peak_resident_bytes is the render's.
  std::uint64_t load_peak_resident_bytes = 0;
  ChunkTraffic traffic;                   // data mode: its chunks and the rays it sent and answered
};

struct DistributedRender {
  RenderOutput output;             // rank 0: the whole image; elsewhere this rank's stages, no image
  std::vector<RankReport> ranks;   // rank 0: every rank's, in rank order; elsewhere empty
  std::uint64_t range_rays = 0;    // rays a range
  double wall_seconds = 0.0;       // from the common start until the films were summed
  std::uint64_t rays_traced() const;
};

// Collective: every rank calls it with the same plan and an identical world (data mode: each
// with its exchange, which routes the world's chunks).
struct RankSetup {
  ChunkExchange* exchange = nullptr;  // data mode
  std::uint64_t load_peak_resident_bytes = 0;
};
DistributedRender render_shared(const MpiSession& session, const RenderPlan& plan, const World& world,
                                const Camera& camera, const std::function<void(const Progress&)>& on_progress = {},
                                const RankSetup& setup = {});

// distribute.range_rays, or when 0 the image's rays over 64 ranges a rank, at least 16 batches.
std::uint64_t range_rays_for(const RenderPlan& plan, int ranks);

}  // namespace wavetrace
