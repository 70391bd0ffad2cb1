// distribute.mode = data: which rank owns which chunk of a chunked world, and the messages
// that carry a round's rays to the owners of their chunks and the hits back.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "wavetrace/accel/chunked/chunk_router.hpp"
#include "wavetrace/distribute/mpi_session.hpp"
#include "wavetrace/setup/render_plan.hpp"

namespace wavetrace {

// What one rank's exchange did.
struct ChunkTraffic {
  std::uint64_t chunks_owned = 0, triangles_owned = 0;
  std::uint64_t chunks_copied = 0, triangles_copied = 0;  // others' chunks it answers itself (distribute.replicate)
  std::uint64_t queries_sent = 0, rays_sent = 0, bytes_sent = 0;  // its rounds' rays to owners, and their answers back
  std::uint64_t queries_answered = 0, rays_answered = 0;          // others' rays it answered
  double wait_seconds = 0.0;  // its tracing threads waiting for answers (serving others meanwhile)
};

// How the ranks share a chunked world's chunks.
struct ChunkSharing {
  // Runs of consecutive chunks (chunks follow the scene's order, so a run is a region) are
  // dealt about equal in triangles (memory) or in `rays_due` (work).
  DistributeBalance balance = DistributeBalance::triangles;
  // This share of the world's triangles, the chunks with the most `rays_due` a triangle first,
  // is answered by every rank itself.
  double replicate = 0.0;
  // The rays each chunk was asked about by probe_rays_due (one count a chunk; the same on every
  // rank, since every rank counts the same probe): needed by balance = rays and replicate > 0.
  std::vector<std::uint64_t> rays_due;
};

// Wire formats (little-endian, as this machine writes them; all ranks run one build):
//   query, tag kQuery:  u32 query (ChunkQuery), u32 reply tag, u32 groups G, u32 rays N;
//     G x {u32 chunk, u32 rays}, the groups' rays one after another in this order; then the
//     ray columns, each N values: f32 origin_x, origin_y, origin_z, direction_x, direction_y,
//     direction_z, tmin, tmax; u8 kind.
//   answer, the query's reply tag: the hit columns of HitBatch (WAVETRACE_HIT_COLUMNS), each N
//     values of 4 bytes in the query's ray order: f32 t, u32 primitive (the chunk's own ids),
//     f32 u, v, point_x, point_y, point_z, normal_x, normal_y, normal_z, u32 material.
//   done, tag kDone: empty; a rank's render has finished and it asks nothing more.
class ChunkExchange final : public ChunkRouter {
 public:
  // Deals the chunks to the ranks as `sharing` says (every rank the same deal) and routes
  // `chunks`. Throws std::invalid_argument where `sharing` needs rays_due and has none.
  ChunkExchange(const MpiSession& session, ChunkSet& chunks, const ChunkSharing& sharing = {});
  ~ChunkExchange() override;
  ChunkExchange(const ChunkExchange&) = delete;
  ChunkExchange& operator=(const ChunkExchange&) = delete;

  bool is_local(std::size_t chunk) const override { return owner_[chunk] == session_.rank() || replicated_[chunk]; }
  void answer_elsewhere(ChunkQuery query, const RayBatch& rays, HitBatch& hits, std::span<const std::uint32_t> chunk_start,
                        const std::function<void()>& local_work) const override;
  void meanwhile() const override;  // answers every query waiting here

  // After this rank's render: answers the others' rays until every rank has finished its own.
  void finish();
  ChunkTraffic traffic() const;
  int owner(std::size_t chunk) const { return owner_[chunk]; }
  bool replicated(std::size_t chunk) const { return replicated_[chunk]; }

 private:
  bool answer_one_query() const;  // answers one query waiting here, if there is one
  void send(std::vector<std::byte> message, int destination, int tag) const;
  void progress_sends() const;    // frees the buffers of sends that completed

  const MpiSession& session_;
  ChunkSet& chunks_;
  std::vector<int> owner_;
  std::vector<bool> replicated_;  // answered by every rank (never asked of its owner)
  // Whether this round asks `rank` about `chunk`: its owner, and not a chunk every rank holds.
  bool asks(std::size_t chunk, int rank) const { return owner_[chunk] == rank && !replicated_[chunk]; }
  struct Outgoing;
  mutable std::mutex outbox_mutex_;
  mutable std::vector<Outgoing*> outbox_;
  mutable std::atomic<std::uint64_t> queries_sent_{0}, rays_sent_{0}, bytes_sent_{0};
  mutable std::atomic<std::uint64_t> queries_answered_{0}, rays_answered_{0};
  mutable std::atomic<std::uint64_t> wait_nanoseconds_{0};
};

}  // namespace wavetrace
