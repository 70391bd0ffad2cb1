// The exchange's messages (formats in chunk_exchange.hpp). Every send is non-blocking and
// every wait answers others' queries meanwhile: two ranks waiting on each other's answers
// both keep answering, so no rank waits on one that cannot move.
#include "wavetrace/distribute/chunk_exchange.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <thread>

#if WAVETRACE_HAVE_MPI
#include <mpi.h>
#endif

namespace wavetrace {
namespace {

constexpr int kQuery = 7101;
constexpr int kDone = 7102;
constexpr int kFirstReplyTag = 8000;  // a tracing thread's own tag: kFirstReplyTag + its number
using Clock = std::chrono::steady_clock;

// Each thread that waits for answers has a tag of its own, so answers find their thread.
int reply_tag_of_this_thread() {
  static std::atomic<int> next{0};
  thread_local const int tag = kFirstReplyTag + next.fetch_add(1);
  return tag;
}

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
  // A probe that met nothing cannot weigh the chunks: triangles do.
  const bool by_rays = sharing.balance == DistributeBalance::rays && rays > 0;
  const auto weight = [&](std::size_t c) {
    return by_rays ? sharing.rays_due[c] : std::uint64_t(chunks.chunk_triangles(c));
  };
  const std::uint64_t total = by_rays ? rays : triangles;
  // Rank r owns the chunks whose weight's middle falls in [r, r + 1) * total / ranks: runs of
  // about equal weight, every rank at least one chunk where there are enough.
  std::uint64_t before = 0;
  for (std::size_t c = 0; c < chunks.chunk_count(); ++c) {
    const std::uint64_t middle = before + weight(c) / 2;
    owner_[c] = static_cast<int>(std::min<std::uint64_t>(std::uint64_t(session.ranks()) * middle / std::max<std::uint64_t>(total, 1),
                                                         std::uint64_t(session.ranks() - 1)));
    before += weight(c);
  }
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
  chunks_.route(this);
}

ChunkExchange::~ChunkExchange() {
  chunks_.route(nullptr);
  for (Outgoing* outgoing : outbox_) delete outgoing;  // finish() completed them; after an error MPI_Abort ends all
}

void ChunkExchange::send(std::vector<std::byte> message, int destination, int tag) const {
#if WAVETRACE_HAVE_MPI
  auto* outgoing = new Outgoing{std::move(message)};
  MPI_Isend(outgoing->bytes.data(), static_cast<int>(outgoing->bytes.size()), MPI_BYTE, destination, tag, MPI_COMM_WORLD,
            &outgoing->request);
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
                                     const std::function<void()>& local_work) const {
#if WAVETRACE_HAVE_MPI
  const int reply_tag = reply_tag_of_this_thread();
  // One query per owner with rays due this round, its groups in chunk order.
  std::vector<int> asked;
  for (int owner = 0; owner < session_.ranks(); ++owner) {
    if (owner == session_.rank()) continue;
    std::vector<std::uint32_t> groups;
    std::uint32_t count = 0;
    for (std::size_t c = 0; c + 1 < chunk_start.size(); ++c) {
      const std::uint32_t n = chunk_start[c + 1] - chunk_start[c];
      if (n == 0 || !asks(c, owner)) continue;
      groups.push_back(static_cast<std::uint32_t>(c));
      groups.push_back(n);
      count += n;
    }
    if (count == 0) continue;
    std::vector<std::byte> message;
    message.reserve(16 + groups.size() * 4 + std::size_t(count) * 33);
    Writer out{message};
    out.put32(static_cast<std::uint32_t>(query));
    out.put32(static_cast<std::uint32_t>(reply_tag));
    out.put32(static_cast<std::uint32_t>(groups.size() / 2));
    out.put32(count);
    out.put(groups.data(), groups.size());
    for (const float* column : {rays.origin_x, rays.origin_y, rays.origin_z, rays.direction_x, rays.direction_y,
                                rays.direction_z, rays.tmin, rays.tmax}) {
      for (std::size_t g = 0; g < groups.size(); g += 2) out.put(column + chunk_start[groups[g]], groups[g + 1]);
    }
    static_assert(sizeof(RayKind) == 1);
    for (std::size_t g = 0; g < groups.size(); g += 2) out.put(rays.kind + chunk_start[groups[g]], groups[g + 1]);
    send(std::move(message), owner, kQuery);
    queries_sent_.fetch_add(1, std::memory_order_relaxed);
    rays_sent_.fetch_add(count, std::memory_order_relaxed);
    asked.push_back(owner);
  }
  local_work();
  if (asked.empty()) return;

  const Clock::time_point start = Clock::now();
  std::size_t pending = asked.size();
  std::vector<std::byte> answer;
  while (pending > 0) {
    int arrived = 0;
    MPI_Message message;
    MPI_Status status;
    MPI_Improbe(MPI_ANY_SOURCE, reply_tag, MPI_COMM_WORLD, &arrived, &message, &status);
    if (!arrived) {
      if (!answer_one_query()) {
        progress_sends();
        std::this_thread::yield();
      }
      continue;
    }
    int bytes = 0;
    MPI_Get_count(&status, MPI_BYTE, &bytes);
    answer.resize(std::size_t(bytes));
    MPI_Mrecv(answer.data(), bytes, MPI_BYTE, &message, MPI_STATUS_IGNORE);
    // The owner's slots in the order its query listed them.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> slots;
    std::uint32_t count = 0;
    for (std::size_t c = 0; c + 1 < chunk_start.size(); ++c) {
      const std::uint32_t n = chunk_start[c + 1] - chunk_start[c];
      if (n == 0 || !asks(c, status.MPI_SOURCE)) continue;
      slots.emplace_back(chunk_start[c], n);
      count += n;
    }
    if (std::size_t(bytes) != std::size_t(count) * HitBatch::kBytesPerHit) {
      throw std::runtime_error("rank " + std::to_string(status.MPI_SOURCE) + " answered a chunk query with " +
                               std::to_string(bytes) + " bytes for " + std::to_string(count) + " rays");
    }
    Reader in{answer};
#define WAVETRACE_READ_HIT_COLUMN(type, name) \
  for (const auto& [first, n] : slots) in.get(hits.name + first, n);
    WAVETRACE_HIT_COLUMNS(WAVETRACE_READ_HIT_COLUMN)
#undef WAVETRACE_READ_HIT_COLUMN
    --pending;
  }
  wait_nanoseconds_.fetch_add(
      std::uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start).count()),
      std::memory_order_relaxed);
#else
  (void)query, (void)rays, (void)hits, (void)chunk_start;
  local_work();  // one rank: every chunk is local
#endif
}

void ChunkExchange::meanwhile() const {
  while (answer_one_query()) {
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
  send(std::move(answer), status.MPI_SOURCE, reply_tag);
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
  return traffic;
}

}  // namespace wavetrace
