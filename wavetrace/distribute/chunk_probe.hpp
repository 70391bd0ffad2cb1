// A probe of the view that measures how much each chunk of a chunked world is asked: the
// measure by which distribute.replicate picks the chunks every rank answers itself.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "wavetrace/accel/chunked/chunk_router.hpp"
#include "wavetrace/scene/camera.hpp"

namespace wavetrace {

// The rays each chunk was asked about (ChunkSet::count_rays_due) by a coarse image's camera
// rays, `width` x about width / aspect, one a pixel, and one cosine-weighted bounce from each
// of their hits: the camera's and the first bounce's view of the work, the same on every rank
// (a pure function of the world, the camera and the size). Call before the world is routed.
// The rays are traced in batches of kProbeBatchRays, `after_batch` called after each: a
// data-parallel rank gives back the pages each batch touched, so that the probe does not make
// the whole world resident.
inline constexpr std::size_t kProbeBatchRays = 1024;
std::vector<std::uint64_t> probe_rays_due(const ChunkSet& chunks, const Camera& camera, float aspect,
                                          std::uint32_t width = 128, const std::function<void()>& after_batch = {});

}  // namespace wavetrace
