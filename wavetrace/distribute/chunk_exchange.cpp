// The exchange's messages (formats in chunk_exchange.hpp). Every send is non-blocking; a
// round waiting for answers is suspended (its thread goes on to other batches) or, where it
// cannot be, answers others' queries while it waits; and a polling thread answers and takes
// in answers when no worker does. So no rank waits on one that cannot move.
#include "wavetrace/distribute/chunk_exchange.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <stdexcept>
#include <thread>

#include <tbb/task.h>
#include <tbb/task_arena.h>

#if WAVETRACE_HAVE_MPI
#include <mpi.h>
#endif

#include "wavetrace/distribute/chunk_deal.hpp"
#include "wavetrace/pipeline/pipeline.hpp"

namespace wavetrace {
namespace {

constexpr int kQuery = 7101;
constexpr int kDone = 7102;
// Each round waiting for answers has a reply tag of its own, so answers find their round;
// tags cycle through kReplyTags values (MPI promises tags up to 32767), far more than the
// rounds a rank has waiting at once (one or a few a batch in flight).
constexpr int kFirstReplyTag = 8000;
constexpr std::uint64_t kReplyTags = 24000;
// Rounds suspended at once: as many as a stage runs calls beyond one a thread (pipeline.hpp);
// past that, a thread that suspended one more round would find no call to start in its place.
constexpr std::uint64_t kMaxSuspendedRounds = kSuspendedCallsPerStage;
using Clock = std::chrono::steady_clock;

// TBB's resumable tasks switch stacks, which AddressSanitizer cannot follow without
// annotations TBB does not make: under it, rounds wait without being suspended.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kRoundsCanSuspend = false;
#else
constexpr bool kRoundsCanSuspend = true;
#endif

struct Writer {
  std::vector<std::byte>& out;
  template <typename T>
  void put(const T* values, std::size_t count) {
    const std::size_t at = out.size();
    out.resize(at + count * sizeof(T));
    std::memcpy(out.data() + at, values, count * sizeof(T));
  }
  void put32(std::uint32_t value) { put(&value, 1); }
};

struct Reader {
  const std::vector<std::byte>& in;
  std::size_t at = 0;
  template <typename T>
  void get(T* values, std::size_t count) {
    if (at + count * sizeof(T) > in.size()) throw std::runtime_error("a chunk exchange message ended early");
    std::memcpy(values, in.data() + at, count * sizeof(T));
    at += count * sizeof(T);
  }
  std::uint32_t get32() {
    std::uint32_t value = 0;
    get(&value, 1);
    return value;
  }
};

// A batch for the rays of one query answered here, grown to the largest query seen.
Batch& answer_batch(std::size_t rays) {
  thread_local std::unique_ptr<Batch> batch;
  if (!batch || batch->rays.capacity() < rays) batch = std::make_unique<Batch>(std::max<std::size_t>(rays, 1024));
  return *batch;
}

}  // namespace

struct ChunkExchange::Outgoing {
  std::vector<std::byte> bytes;
#if WAVETRACE_HAVE_MPI
  MPI_Request request = MPI_REQUEST_NULL;
#endif
};

struct ChunkExchange::AnswerChannel {
#if WAVETRACE_HAVE_MPI
  MPI_Comm comm = MPI_COMM_NULL;
#endif
};

// One round's wait: where each owner's answer goes, and how many are still out. Lives on
// the waiting round's stack; registered under its reply tag before its queries leave, and
// untouched by the receivers once the last answer is in.
struct ChunkExchange::Waiter {
  HitBatch* hits = nullptr;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> slots;  // per rank: (first slot, rays), in query order
  std::vector<std::uint32_t> rays;                                          // per rank: the rays asked of it
  std::size_t pending = 0;  // answers still out (waiters_mutex_)
  std::exception_ptr error;  // an answer that did not fit its query
  std::mutex mutex;          // the hand-over between the last answer and the round's suspension
  bool parked = false, done = false;
  std::atomic<bool> answered{false};  // for a round that spins rather than suspends
#if __TBB_RESUMABLE_TASKS
  tbb::task::suspend_point point{};
  // A suspended round's place among those waiting for answers, given back when it is
  // resumed rather than when it runs again: resumed rounds queue behind fresh ones for the
  // arena's threads, and counted until they ran they kept new rounds from suspending.
  std::atomic<std::uint64_t>* waiting_rounds = nullptr;
#endif

  // The last answer is in: wake the round (it may not have finished suspending yet). Once
  // `answered` is set a round that was not parked may leave and its waiter go, so nothing of
  // the waiter is touched after it; a parked one cannot leave before it is resumed.
  void finish() {
#if __TBB_RESUMABLE_TASKS
    bool resume = false;
    tbb::task::suspend_point resume_point{};
    {
      std::lock_guard lock(mutex);
      done = true;
      resume = parked;
      resume_point = point;
    }
    if (resume) waiting_rounds->fetch_sub(1, std::memory_order_acq_rel);
    answered.store(true, std::memory_order_release);
    if (resume) tbb::task::resume(resume_point);
#else
    answered.store(true, std::memory_order_release);
#endif
  }
#if __TBB_RESUMABLE_TASKS
  // From the suspension's callback: the round's stack is parked; resume it now if its answers
  // came in the meantime.
  void park(tbb::task::suspend_point at) {
    std::unique_lock lock(mutex);
    if (done) {
      lock.unlock();
      waiting_rounds->fetch_sub(1, std::memory_order_acq_rel);
      tbb::task::resume(at);
      return;
    }
    parked = true;
    point = at;
  }
#endif
};

ChunkExchange::ChunkExchange(const MpiSession& session, ChunkSet& chunks, const ChunkSharing& sharing)
    : session_(session), chunks_(chunks), owner_(chunks.chunk_count(), 0), replicated_(chunks.chunk_count(), false) {
  const bool needs_rays = sharing.balance == DistributeBalance::rays || sharing.replicate > 0.0;
  if (needs_rays && sharing.rays_due.size() != chunks.chunk_count()) {
    throw std::invalid_argument("distribute: balance by rays and replicate need one probe count a chunk");
  }
  std::uint64_t triangles = 0, rays = 0;
  for (std::size_t c = 0; c < chunks.chunk_count(); ++c) {
    triangles += chunks.chunk_triangles(c);
    if (needs_rays) rays += sharing.rays_due[c];
  }
  // A probe that met nothing cannot weigh the chunks: their structures' bytes do.
  const DistributeBalance balance =
      sharing.balance == DistributeBalance::rays && rays == 0 ? DistributeBalance::bytes : sharing.balance;
  std::vector<std::uint64_t> weights(chunks.chunk_count());
  for (std::size_t c = 0; c < weights.size(); ++c) {
    weights[c] = balance == DistributeBalance::rays        ? sharing.rays_due[c]
                 : balance == DistributeBalance::triangles ? std::uint64_t(chunks.chunk_triangles(c))
                                                           : std::uint64_t(chunks.chunk_bytes(c));
  }
  owner_ = deal_chunk_runs(weights, session.ranks());
  if (sharing.replicate > 0.0) {
    // The most rays a triangle first: the traffic a copy saves for the memory it costs. Ties in chunk order.
    const std::vector<std::uint64_t>& rays_due = sharing.rays_due;
    std::vector<std::size_t> order(chunks.chunk_count());
    for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
    const auto density = [&](std::size_t c) {
      return double(rays_due[c]) / double(std::max<std::size_t>(chunks.chunk_triangles(c), 1));
    };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return density(a) > density(b); });
    const double allowed = sharing.replicate * double(triangles);
    double copied = 0.0;
    for (const std::size_t c : order) {
      if (rays_due[c] == 0 || copied + double(chunks.chunk_triangles(c)) > allowed) continue;
      replicated_[c] = true;
      copied += double(chunks.chunk_triangles(c));
    }
  }
  // WAVETRACE_SUSPEND_ROUNDS=0 keeps every round waiting on its thread, for the A/B.
  const char* suspend_setting = std::getenv("WAVETRACE_SUSPEND_ROUNDS");
  rounds_suspend_ = kRoundsCanSuspend && !(suspend_setting != nullptr && std::string(suspend_setting) == "0");
  answers_ = std::make_unique<AnswerChannel>();
#if WAVETRACE_HAVE_MPI
  if (session_.distributed()) {
    MPI_Comm_dup(MPI_COMM_WORLD, &answers_->comm);  // collective: every rank makes its exchange here
    poller_ = std::thread([this] { poll_until_stopped(); });
  }
#endif
  chunks_.route(this);
}

ChunkExchange::~ChunkExchange() {
  stop_polling_.store(true, std::memory_order_release);
  if (poller_.joinable()) poller_.join();
  // The answers' communicator is left to MPI_Finalize: freeing it is collective, and this
  // runs on a failing rank's way out too.
  chunks_.route(nullptr);
  for (Outgoing* outgoing : outbox_) delete outgoing;  // finish() completed them; after an error MPI_Abort ends all
}

void ChunkExchange::poll_until_stopped() {
  // A short sleep when nothing came: the poller shares the cores with the workers, and an
  // answer waits at most this long when no worker looks. 100 us rather than 20: each wake is
  // a system call and a switch that a rank's one worker pays for (two ranks of one thread on
  // room:64M, 7.5-7.9 s against 8.2-8.5; 200 us no faster; four ranks, or two of two
  // threads, the same either way: distributed.md, "The poller's sleep").
  constexpr auto kIdle = std::chrono::microseconds(100);
  try {
    while (!stop_polling_.load(std::memory_order_acquire)) {
      bool worked = receive_one_answer();
      worked = answer_one_query() || worked;
      progress_sends();
      if (!worked) std::this_thread::sleep_for(kIdle);
    }
  } catch (const std::exception& error) {
    // Every rank would wait on this one: say why and end them all, as a failed rank does.
    std::fprintf(stderr, "wavetrace: rank %d: %s\n", session_.rank(), error.what());
    session_.abort(1);
  }
}

void ChunkExchange::send(std::vector<std::byte> message, int destination, int tag, bool answer) const {
#if WAVETRACE_HAVE_MPI
  auto* outgoing = new Outgoing{std::move(message)};
  MPI_Isend(outgoing->bytes.data(), static_cast<int>(outgoing->bytes.size()), MPI_BYTE, destination, tag,
            answer ? answers_->comm : MPI_COMM_WORLD, &outgoing->request);
  bytes_sent_.fetch_add(outgoing->bytes.size(), std::memory_order_relaxed);
  std::lock_guard lock(outbox_mutex_);
  outbox_.push_back(outgoing);
#endif
}

void ChunkExchange::progress_sends() const {
#if WAVETRACE_HAVE_MPI
  std::lock_guard lock(outbox_mutex_);
  std::erase_if(outbox_, [](Outgoing* outgoing) {
    int done = 0;
    MPI_Test(&outgoing->request, &done, MPI_STATUS_IGNORE);
    if (done) delete outgoing;
    return done != 0;
  });
#endif
}

void ChunkExchange::answer_elsewhere(ChunkQuery query, const RayBatch& rays, HitBatch& hits,
                                     std::span<const std::uint32_t> chunk_start,
                                     const std::function<void()>& local_work, bool may_suspend) const {
#if WAVETRACE_HAVE_MPI
  Waiter waiter;
  waiter.hits = &hits;
  waiter.slots.resize(std::size_t(session_.ranks()));
  waiter.rays.assign(std::size_t(session_.ranks()), 0);
  // Per owner, its chunks' groups in chunk order: (chunk, rays) pairs, as the query lists them.
  std::vector<std::vector<std::uint32_t>> groups(std::size_t(session_.ranks()));
  for (std::size_t c = 0; c + 1 < chunk_start.size(); ++c) {
    const std::uint32_t n = chunk_start[c + 1] - chunk_start[c];
    if (n == 0 || owner_[c] == session_.rank() || replicated_[c]) continue;
    const auto owner = std::size_t(owner_[c]);
    waiter.slots[owner].emplace_back(chunk_start[c], n);
    waiter.rays[owner] += n;
    groups[owner].push_back(static_cast<std::uint32_t>(c));
    groups[owner].push_back(n);
  }
  for (int owner = 0; owner < session_.ranks(); ++owner) waiter.pending += waiter.rays[std::size_t(owner)] > 0 ? 1 : 0;
  if (waiter.pending == 0) {
    local_work();
    return;
  }
  const int reply_tag = kFirstReplyTag + int(next_reply_.fetch_add(1, std::memory_order_relaxed) % kReplyTags);
  {
    // Registered before any query leaves, so that every answer finds its round.
    std::lock_guard lock(waiters_mutex_);
    if (!waiters_.emplace(reply_tag, &waiter).second) {
      throw std::logic_error("chunk exchange: more rounds waiting at once than reply tags");
    }
  }
  // The last answer unregisters the round; a round left by an exception unregisters itself,
  // so that no later answer writes into a stack that is gone.
  struct Unregister {
    const ChunkExchange& exchange;
    int tag;
    const Waiter* waiter;
    ~Unregister() {
      std::lock_guard lock(exchange.waiters_mutex_);
      const auto found = exchange.waiters_.find(tag);
      if (found != exchange.waiters_.end() && found->second == waiter) exchange.waiters_.erase(found);
    }
  } unregister{*this, reply_tag, &waiter};
  // One query per owner with rays due this round, its groups in chunk order.
  for (int owner = 0; owner < session_.ranks(); ++owner) {
    const std::uint32_t count = waiter.rays[std::size_t(owner)];
    if (count == 0) continue;
    const std::vector<std::uint32_t>& owner_groups = groups[std::size_t(owner)];
    std::vector<std::byte> message;
    message.reserve(16 + owner_groups.size() * 4 + std::size_t(count) * 33);
    Writer out{message};
    out.put32(static_cast<std::uint32_t>(query));
    out.put32(static_cast<std::uint32_t>(reply_tag));
    out.put32(static_cast<std::uint32_t>(owner_groups.size() / 2));
    out.put32(count);
    out.put(owner_groups.data(), owner_groups.size());
    for (const float* column : {rays.origin_x, rays.origin_y, rays.origin_z, rays.direction_x, rays.direction_y,
                                rays.direction_z, rays.tmin, rays.tmax}) {
      for (std::size_t g = 0; g < owner_groups.size(); g += 2) {
        out.put(column + chunk_start[owner_groups[g]], owner_groups[g + 1]);
      }
    }
    static_assert(sizeof(RayKind) == 1);
    for (std::size_t g = 0; g < owner_groups.size(); g += 2) {
      out.put(rays.kind + chunk_start[owner_groups[g]], owner_groups[g + 1]);
    }
    send(std::move(message), owner, kQuery);
    queries_sent_.fetch_add(1, std::memory_order_relaxed);
    rays_sent_.fetch_add(count, std::memory_order_relaxed);
  }
  local_work();

  const Clock::time_point start = Clock::now();
#if __TBB_RESUMABLE_TASKS
  // Suspended only inside a task of an arena, with the poller there to resume it should every
  // worker be idle. A suspended round holds its scratch (about 130 KB a batch of 1,024 rays)
  // and a stack: past kMaxSuspendedRounds suspended with their answers still out, a round
  // waits on its thread as without. Rounds resumed and waiting for a thread no longer count:
  // counted, they kept two ranks of one thread spinning on most rounds (1 in 4 suspended),
  // 7% slower than now (distributed.md, "Resumed rounds give their place back").
  const bool suspend = rounds_suspend_ && may_suspend && poller_.joinable() &&
                       tbb::this_task_arena::current_thread_index() != tbb::task_arena::not_initialized;
  if (suspend && !waiter.answered.load(std::memory_order_acquire)) {
    if (rounds_awaiting_answers_.fetch_add(1, std::memory_order_acq_rel) < kMaxSuspendedRounds) {
      rounds_suspended_.fetch_add(1, std::memory_order_relaxed);
      waiter.waiting_rounds = &rounds_awaiting_answers_;  // given back by the resume
      tbb::task::suspend([&waiter](tbb::task::suspend_point point) { waiter.park(point); });
    } else {
      rounds_awaiting_answers_.fetch_sub(1, std::memory_order_acq_rel);
    }
  }
#else
  (void)may_suspend;
#endif
  while (!waiter.answered.load(std::memory_order_acquire)) {
    if (!receive_one_answer() && !answer_one_query()) {
      progress_sends();
      std::this_thread::yield();
    }
  }
  wait_nanoseconds_.fetch_add(
      std::uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start).count()),
      std::memory_order_relaxed);
  if (waiter.error) std::rethrow_exception(waiter.error);
#else
  (void)query, (void)rays, (void)hits, (void)chunk_start, (void)may_suspend;
  local_work();  // one rank: every chunk is local
#endif
}

bool ChunkExchange::receive_one_answer() const {
#if WAVETRACE_HAVE_MPI
  if (answers_->comm == MPI_COMM_NULL) return false;
  int arrived = 0;
  MPI_Message message;
  MPI_Status status;
  MPI_Improbe(MPI_ANY_SOURCE, MPI_ANY_TAG, answers_->comm, &arrived, &message, &status);
  if (!arrived) return false;
  int bytes = 0;
  MPI_Get_count(&status, MPI_BYTE, &bytes);
  std::vector<std::byte> answer(static_cast<std::size_t>(bytes));
  MPI_Mrecv(answer.data(), bytes, MPI_BYTE, &message, MPI_STATUS_IGNORE);
  Waiter* waiter = nullptr;
  bool last = false;
  {
    std::lock_guard lock(waiters_mutex_);
    const auto found = waiters_.find(status.MPI_TAG);
    if (found == waiters_.end()) {
      throw std::runtime_error("rank " + std::to_string(status.MPI_SOURCE) + " answered a round (tag " +
                               std::to_string(status.MPI_TAG) + ") no one here waits for");
    }
    waiter = found->second;
    const auto source = std::size_t(status.MPI_SOURCE);
    const std::uint32_t count = source < waiter->rays.size() ? waiter->rays[source] : 0;
    if (std::size_t(bytes) != std::size_t(count) * HitBatch::kBytesPerHit) {
      waiter->error = std::make_exception_ptr(std::runtime_error(
          "rank " + std::to_string(status.MPI_SOURCE) + " answered a chunk query with " + std::to_string(bytes) +
          " bytes for " + std::to_string(count) + " rays"));
    } else {
      // The owner's slots in the order its query listed them.
      HitBatch& hits = *waiter->hits;
      Reader in{answer};
#define WAVETRACE_READ_HIT_COLUMN(type, name) \
  for (const auto& [first, n] : waiter->slots[source]) in.get(hits.name + first, n);
      WAVETRACE_HIT_COLUMNS(WAVETRACE_READ_HIT_COLUMN)
#undef WAVETRACE_READ_HIT_COLUMN
    }
    last = --waiter->pending == 0;
    if (last) waiters_.erase(found);
  }
  if (last) waiter->finish();
  return true;
#else
  return false;
#endif
}

void ChunkExchange::meanwhile() const {
  while (answer_one_query() || receive_one_answer()) {
  }
}

bool ChunkExchange::answer_one_query() const {
#if WAVETRACE_HAVE_MPI
  int arrived = 0;
  MPI_Message message;
  MPI_Status status;
  MPI_Improbe(MPI_ANY_SOURCE, kQuery, MPI_COMM_WORLD, &arrived, &message, &status);
  if (!arrived) return false;
  int bytes = 0;
  MPI_Get_count(&status, MPI_BYTE, &bytes);
  std::vector<std::byte> query_bytes(static_cast<std::size_t>(bytes));
  MPI_Mrecv(query_bytes.data(), bytes, MPI_BYTE, &message, MPI_STATUS_IGNORE);
  Reader in{query_bytes};
  const auto query = static_cast<ChunkQuery>(in.get32());
  const int reply_tag = static_cast<int>(in.get32());
  const std::uint32_t group_count = in.get32();
  const std::uint32_t count = in.get32();
  std::vector<std::uint32_t> groups(std::size_t(group_count) * 2);
  in.get(groups.data(), groups.size());
  Batch& batch = answer_batch(count);
  RayBatch& rays = batch.rays;
  for (float* column : {rays.origin_x, rays.origin_y, rays.origin_z, rays.direction_x, rays.direction_y,
                        rays.direction_z, rays.tmin, rays.tmax}) {
    in.get(column, count);
  }
  in.get(rays.kind, count);
  std::fill(rays.flags, rays.flags + count, ray_flags::alive);
  rays.count = count;
  std::uint32_t begin = 0;
  for (std::size_t g = 0; g < groups.size(); g += 2) {
    if (groups[g] >= chunks_.chunk_count() || owner_[groups[g]] != session_.rank() || begin + groups[g + 1] > count) {
      throw std::runtime_error("rank " + std::to_string(status.MPI_SOURCE) + " asked about chunk " +
                               std::to_string(groups[g]) + ", which this rank does not own");
    }
    chunks_.query_chunk(groups[g], query, rays, batch.hits, RayRange{begin, begin + groups[g + 1]});
    begin += groups[g + 1];
  }
  std::vector<std::byte> answer;
  answer.reserve(std::size_t(count) * HitBatch::kBytesPerHit);
  Writer out{answer};
#define WAVETRACE_WRITE_HIT_COLUMN(type, name) out.put(batch.hits.name, count);
  WAVETRACE_HIT_COLUMNS(WAVETRACE_WRITE_HIT_COLUMN)
#undef WAVETRACE_WRITE_HIT_COLUMN
  send(std::move(answer), status.MPI_SOURCE, reply_tag, /*answer=*/true);
  queries_answered_.fetch_add(1, std::memory_order_relaxed);
  rays_answered_.fetch_add(count, std::memory_order_relaxed);
  return true;
#else
  return false;
#endif
}

void ChunkExchange::finish() {
#if WAVETRACE_HAVE_MPI
  if (!session_.distributed()) return;
  for (int rank = 0; rank < session_.ranks(); ++rank) {
    if (rank != session_.rank()) send({}, rank, kDone);
  }
  int finished = 0;
  while (true) {
    progress_sends();
    {
      std::lock_guard lock(outbox_mutex_);
      if (finished == session_.ranks() - 1 && outbox_.empty()) break;
    }
    int arrived = 0;
    MPI_Message message;
    MPI_Status status;
    MPI_Improbe(MPI_ANY_SOURCE, kDone, MPI_COMM_WORLD, &arrived, &message, &status);
    if (arrived) {
      MPI_Mrecv(nullptr, 0, MPI_BYTE, &message, MPI_STATUS_IGNORE);
      ++finished;
      continue;
    }
    // Idle here steals no core from ranks still rendering: sleep when nothing came.
    if (!answer_one_query()) std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
#endif
}

ChunkTraffic ChunkExchange::traffic() const {
  ChunkTraffic traffic;
  for (std::size_t c = 0; c < owner_.size(); ++c) {
    if (owner_[c] == session_.rank()) {
      ++traffic.chunks_owned;
      traffic.triangles_owned += chunks_.chunk_triangles(c);
      traffic.bytes_owned += chunks_.chunk_bytes(c);
    } else if (replicated_[c]) {
      ++traffic.chunks_copied;
      traffic.triangles_copied += chunks_.chunk_triangles(c);
    }
  }
  traffic.queries_sent = queries_sent_.load();
  traffic.rays_sent = rays_sent_.load();
  traffic.bytes_sent = bytes_sent_.load();
  traffic.queries_answered = queries_answered_.load();
  traffic.rays_answered = rays_answered_.load();
  traffic.wait_seconds = double(wait_nanoseconds_.load()) * 1e-9;
  traffic.rounds_suspended = rounds_suspended_.load();
  return traffic;
}

}  // namespace wavetrace
