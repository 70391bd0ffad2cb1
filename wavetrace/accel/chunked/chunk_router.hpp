// Chunks answered elsewhere: a chunked world whose chunks are owned by several processes (a
// data-parallel render, wavetrace/distribute/) hands each round's rays for the chunks it does
// not hold to a router, which brings back the hits their owners found.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

class Accelerator;

// Which query a round asks of its chunks.
enum class ChunkQuery : std::uint32_t { closest = 0, any = 1, coherent = 2 };

class ChunkRouter {
 public:
  virtual ~ChunkRouter() = default;
  virtual bool is_local(std::size_t chunk) const = 0;
  // One round: slots [chunk_start[c], chunk_start[c + 1]) of `rays` are due at chunk c. For
  // every chunk not local, writes into the same slots of `hits` what that chunk's accelerator
  // would have (primitive ids the chunk's own), running `local_work` (the local chunks'
  // queries) while the answers travel. With `may_suspend`, a caller running as a TBB task
  // may be suspended until its answers are in, its thread free for other tasks meanwhile,
  // and resumed on any thread of the arena: such a caller keeps nothing in thread-local
  // state across the call.
  virtual void answer_elsewhere(ChunkQuery query, const RayBatch& rays, HitBatch& hits,
                                std::span<const std::uint32_t> chunk_start, const std::function<void()>& local_work,
                                bool may_suspend) const = 0;
  // Called between the local chunks' queries of a round: a chance to answer the rays others
  // wait for without keeping them waiting a whole round.
  virtual void meanwhile() const {}
};

// The chunks of a chunked world, for the processes that own and answer them.
class ChunkSet {
 public:
  virtual ~ChunkSet() = default;
  virtual std::size_t chunk_count() const = 0;
  virtual std::size_t chunk_triangles(std::size_t chunk) const = 0;
  virtual std::size_t chunk_bytes(std::size_t chunk) const = 0;  // its structure's (MemoryReport::total)
  // Rays [range) of `rays` against chunk `chunk` alone, as a round would ask it.
  virtual void query_chunk(std::size_t chunk, ChunkQuery query, const RayBatch& rays, HitBatch& hits,
                           RayRange range) const = 0;
  // From now on the chunks the router does not hold are asked through it (null: every chunk
  // here). Set between renders, never during one.
  virtual void route(const ChunkRouter* router) = 0;
  // Closest hits of every ray of `rays`, as intersect_closest finds them, adding to
  // `rays_due[c]` the rays each chunk c was asked about (rays_due holds chunk_count()): the
  // work each chunk does for these rays. Before route() only (throws std::logic_error after).
  virtual void count_rays_due(const RayBatch& rays, HitBatch& hits, std::span<std::uint64_t> rays_due) const = 0;
};

}  // namespace wavetrace
