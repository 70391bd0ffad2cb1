// The dealer's protocol: a rank sends rank 0 an empty request (tag kAsk) and receives two
// 64-bit words (tag kRange): the range's first ray and its count; count 0 means no more,
// and is each rank's last answer.
#include "wavetrace/distribute/ray_range_dealer.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#if WAVETRACE_HAVE_MPI
#include <mpi.h>
#endif

namespace wavetrace {
namespace {

constexpr int kAsk = 7001;
constexpr int kRange = 7002;
using Clock = std::chrono::steady_clock;

}  // namespace

RayRangeDealer::RayRangeDealer(const MpiSession& session, std::uint64_t total_rays, std::uint64_t range_rays)
    : session_(session), total_rays_(total_rays), range_rays_(range_rays) {
  if (range_rays == 0) throw std::invalid_argument("a ray range dealer needs ranges of at least one ray");
  if (session.rank() == 0 && session.distributed()) server_ = std::thread([this] { serve(); });
}

RayRangeDealer::~RayRangeDealer() { finish(); }

void RayRangeDealer::finish() {
  if (server_.joinable()) server_.join();
}

CameraRayRange RayRangeDealer::draw() {
  const std::uint64_t first = next_first_.fetch_add(range_rays_, std::memory_order_relaxed);
  if (first >= total_rays_) return {};
  return {first, std::min(range_rays_, total_rays_ - first)};
}

CameraRayRange RayRangeDealer::next() {
  CameraRayRange range;
  if (session_.rank() == 0) {
    range = draw();
  } else {
#if WAVETRACE_HAVE_MPI
    const Clock::time_point start = Clock::now();
    std::uint64_t answer[2] = {};
    MPI_Send(nullptr, 0, MPI_BYTE, 0, kAsk, MPI_COMM_WORLD);
    MPI_Recv(answer, 2, MPI_UINT64_T, 0, kRange, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    wait_seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
    range = {answer[0], answer[1]};
#endif
  }
  if (range.count > 0) ++ranges_taken_;
  return range;
}

void RayRangeDealer::serve() {
#if WAVETRACE_HAVE_MPI
  int told_done = 0;
  while (told_done < session_.ranks() - 1) {
    // A blocking receive would spin a core for the whole render (Open MPI polls): test, and
    // sleep between tests. A range is many batches, so 1 ms late costs nothing.
    MPI_Request request;
    MPI_Irecv(nullptr, 0, MPI_BYTE, MPI_ANY_SOURCE, kAsk, MPI_COMM_WORLD, &request);
    MPI_Status status;
    for (int arrived = 0;;) {
      MPI_Test(&request, &arrived, &status);
      if (arrived) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    const CameraRayRange range = draw();
    const std::uint64_t answer[2] = {range.first, range.count};
    MPI_Send(answer, 2, MPI_UINT64_T, status.MPI_SOURCE, kRange, MPI_COMM_WORLD);
    if (range.count == 0) ++told_done;
  }
#endif
}

}  // namespace wavetrace
