// A probe of the view that measures how much each chunk of a chunked world is asked: the
// measure by which distribute.replicate picks the chunks every rank answers itself.
#pragma once

#include <cstdint>
#include <vector>

#include "wavetrace/accel/chunked/chunk_router.hpp"
#include "wavetrace/scene/camera.hpp"

namespace wavetrace {

// The rays each chunk was asked about (ChunkSet::count_rays_due) by a coarse image's camera
// rays, `width` x about width / aspect, one a pixel, and one cosine-weighted bounce from each
// of their hits: the camera's and the first bounce's view of the work, the same on every rank
// (a pure function of the world, the camera and the size). Call before the world is routed.
std::vector<std::uint64_t> probe_rays_due(const ChunkSet& chunks, const Camera& camera, float aspect,
                                          std::uint32_t width = 128);

}  // namespace wavetrace
