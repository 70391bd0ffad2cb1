// A world of chunks: the scene's triangles cut into runs of at most `chunk_triangles`, each
// built into a sub-accelerator of its own (its build temporaries freed once it is built;
// as many chunks built at once as there are worker threads and memory for them), joined by
// a top-level BVH over the chunks' boxes. The chunk is the unit of building, of saving
// (each chunk's sections in a world file) and of paging (docs/memory.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/scene/triangle_source.hpp"

namespace wavetrace {

inline constexpr std::size_t kMinChunkTriangles = 1024;
inline constexpr std::size_t kMaxChunkTriangles = std::size_t{1} << 30;

struct ChunkRange {
  std::size_t first = 0;  // the chunk's first triangle in the source's numbering
  std::size_t count = 0;
};

// Cuts [0, triangles) into chunks of at most `chunk_triangles`: each object (or part, such as
// a face of a room's shell) into equal runs, and no chunk spans two. Merging small objects
// was measured worse: a chunk holding the room's shell and the light has the room's box,
// so every ray from inside visited it first and found the far wall before the near objects
// (primary rays on room:8M, 1M chunks: bvh 0.88x, raystrips 0.84x of monolithic).
std::vector<ChunkRange> plan_chunks(std::span<const std::size_t> object_starts, std::size_t triangles,
                                    std::size_t chunk_triangles);

// Builds a chunk's sub-accelerator from the chunk's own mesh (triangles numbered from 0).
using ChunkBuilder = std::function<std::unique_ptr<Accelerator>(const TriangleMesh&)>;

class SectionWriter;

// Told of each chunk of a streamed build as it is built, on the thread that built it
// (several chunks are built at once): the chunk's index, its first triangle's id in the
// source, its mesh and its sub-accelerator (triangles numbered from 0), before the chunk is
// written and freed. For what a build makes beside the world from every chunk (a proxy,
// proxy_by_chunks.hpp).
using ChunkObserver =
    std::function<void(std::size_t chunk, std::size_t first, const TriangleMesh& mesh, const Accelerator& built)>;

// Where a build saves its chunks as they are built, so that a world larger than memory is
// never held whole: each chunk's sections go to `out` under `prefix` + "chunk.N/" once its
// wave is built, and the chunk's structure is freed (all but chunk 0's, which answers
// represented_point and build_notes). The world built so is for saving, to the same writer
// under the same prefix, and nothing else: tracing it throws std::logic_error.
struct ChunkStream {
  SectionWriter& out;
  std::string prefix;
  ChunkObserver observe = {};  // none when empty
};

// `keeps_mesh`: the sub-accelerators read their chunk's mesh in place (bvh), so the world
// keeps each chunk's mesh; otherwise (hmq, raystrips) a chunk's mesh is freed once built.
// `at_once_limit`: at most this many chunks built at the same time (0: one per thread, as
// memory allows). Primitive ids in hits are the source's; throws std::invalid_argument for
// chunk_triangles outside [kMinChunkTriangles, kMaxChunkTriangles].
std::unique_ptr<Accelerator> make_chunked_accelerator(const TriangleSource& source, std::size_t chunk_triangles,
                                                      const ChunkBuilder& build_chunk, bool keeps_mesh,
                                                      const ChunkStream* stream = nullptr, std::size_t at_once_limit = 0);

// A chunked world saved under the loader's prefix (format in chunked_accelerator.cpp), each
// chunk's accelerator loaded by `load_chunk` from its own prefix.
class SectionLoader;
using ChunkLoader = std::function<std::unique_ptr<Accelerator>(SectionLoader&)>;
// The saved kind (SavedKind::type) of a chunked world.
inline constexpr std::string_view kChunkedKind = "chunked";
std::unique_ptr<Accelerator> load_chunked_accelerator(SectionLoader& in, const ChunkLoader& load_chunk);

}  // namespace wavetrace
