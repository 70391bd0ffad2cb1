// distribute.mode = data: which rank owns which chunk of a chunked world, and the messages
// that carry a round's rays to the owners of their chunks and the hits back.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#include "wavetrace/accel/chunked/chunk_router.hpp"
#include "wavetrace/distribute/mpi_session.hpp"
#include "wavetrace/setup/render_plan.hpp"

namespace wavetrace {

// What one rank's exchange did.
struct ChunkTraffic {
  std::uint64_t chunks_owned = 0, triangles_owned = 0, bytes_owned = 0;  // bytes: the owned chunks' structures
  std::uint64_t chunks_copied = 0, triangles_copied = 0;  // others' chunks it answers itself (distribute.replicate)
  std::uint64_t queries_sent = 0, rays_sent = 0, bytes_sent = 0;  // its rounds' rays to owners, and their answers back
  std::uint64_t queries_answered = 0, rays_answered = 0;          // others' rays it answered
  // Its rounds waiting for answers, summed: a suspended round's thread traces other batches
  // meanwhile, a round that cannot be suspended serves others' queries while it waits.
  double wait_seconds = 0.0;
  std::uint64_t rounds_suspended = 0;  // rounds whose thread went on to other work while their rays travelled
};

// How the ranks share a chunked world's chunks.
struct ChunkSharing {
  // Runs of consecutive chunks (chunks follow the scene's order, so a run is a region) are
  // dealt with the heaviest as light as it can be, weighed in structure bytes (a rank's
  // memory), triangles or `rays_due` (work): chunk_deal.hpp.
  DistributeBalance balance = DistributeBalance::bytes;
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
//   answer, the query's reply tag, on the exchange's own communicator (a duplicate of
//     MPI_COMM_WORLD, so that any answer can be probed for without taking a query or a done):
//     the hit columns of HitBatch (WAVETRACE_HIT_COLUMNS), each N
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
  // A round that may be suspended and runs as a TBB task is suspended until its answers are
  // in (rays that travel on: its thread traces other batches meanwhile); an answer
  // wherever it is received goes to its round, and the last one resumes it.
  void answer_elsewhere(ChunkQuery query, const RayBatch& rays, HitBatch& hits, std::span<const std::uint32_t> chunk_start,
                        const std::function<void()>& local_work, bool may_suspend) const override;
  void meanwhile() const override;  // answers every query waiting here and takes in every answer arrived

  // After this rank's render: answers the others' rays until every rank has finished its own.
  void finish();
  ChunkTraffic traffic() const;
  int owner(std::size_t chunk) const { return owner_[chunk]; }
  bool replicated(std::size_t chunk) const { return replicated_[chunk]; }

 private:
  struct Waiter;
  bool answer_one_query() const;    // answers one query waiting here, if there is one
  bool receive_one_answer() const;  // gives one answer that arrived to its round, if one did
  void send(std::vector<std::byte> message, int destination, int tag, bool answer = false) const;
  void progress_sends() const;      // frees the buffers of sends that completed
  // The thread that keeps the exchange moving while every worker is busy or every round is
  // suspended: takes in answers (resuming their rounds) and answers queries, sleeping a
  // little when nothing came.
  void poll_until_stopped();

  const MpiSession& session_;
  ChunkSet& chunks_;
  std::vector<int> owner_;
  std::vector<bool> replicated_;  // answered by every rank (never asked of its owner)
  struct Outgoing;
  mutable std::mutex outbox_mutex_;
  mutable std::vector<Outgoing*> outbox_;
  mutable std::atomic<std::uint64_t> queries_sent_{0}, rays_sent_{0}, bytes_sent_{0};
  mutable std::atomic<std::uint64_t> queries_answered_{0}, rays_answered_{0};
  mutable std::atomic<std::uint64_t> wait_nanoseconds_{0}, rounds_suspended_{0}, rounds_awaiting_answers_{0};
  // Rounds waiting for answers, by the reply tag their queries carry (each round its own).
  mutable std::mutex waiters_mutex_;
  mutable std::unordered_map<int, Waiter*> waiters_;
  mutable std::atomic<std::uint64_t> next_reply_{0};
  struct AnswerChannel;  // the communicator answers travel on
  std::unique_ptr<AnswerChannel> answers_;
  bool rounds_suspend_ = false;  // rounds run as tasks may be suspended (not under ASan; WAVETRACE_SUSPEND_ROUNDS=0)
  std::atomic<bool> stop_polling_{false};
  std::thread poller_;
};

}  // namespace wavetrace
