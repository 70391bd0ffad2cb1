// Spill runs through a 1 MiB buffer: the disk sees large sequential writes and reads only.
#include "wavetrace/memory/ray_spill.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>

#include <fcntl.h>
#include <sys/statvfs.h>
#include <sys/types.h>
#include <unistd.h>

#include <fmt/format.h>

namespace wavetrace {
namespace {

constexpr std::size_t kSpillIoBytes = std::size_t{1} << 20;
constexpr std::uint32_t kSortKeyColumns = 1u << 1;  // bit 0 once named the approximate hit

struct BlockHeader {
  std::uint32_t count;
  std::uint32_t columns;
};
static_assert(sizeof(BlockHeader) == 8);

class Timer {
 public:
  explicit Timer(double& seconds) : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}
  ~Timer() { seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  double& seconds_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

std::uint64_t spill_directory_free_bytes(const std::string& directory) {
  struct statvfs info {};
  if (::statvfs(directory.c_str(), &info) != 0) {
    throw SpillError(fmt::format("reorder.spill_dir = {}: {}", directory, std::strerror(errno)));
  }
  // A spill file is made and dropped at once: this is the check that the directory takes one.
  const int fd = ::open(directory.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd < 0) {
    throw SpillError(fmt::format("reorder.spill_dir = {}: cannot create spill files there: {}", directory,
                                 std::strerror(errno)));
  }
  ::close(fd);
  return std::uint64_t(info.f_bavail) * info.f_frsize;
}

SpillRun::SpillRun(const std::string& directory, SpillCounters& counters)
    : directory_(directory), counters_(counters), buffer_(kSpillIoBytes) {
  fd_ = ::open(directory.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd_ < 0) {
    throw SpillError(fmt::format("reorder.spill_dir = {}: cannot create a spill file: {}", directory, std::strerror(errno)));
  }
  ++counters_.runs;
}

SpillRun::~SpillRun() {
  if (fd_ >= 0) ::close(fd_);
}

void SpillRun::flush_writes() {
  Timer timer(counters_.seconds);
  std::size_t done = 0;
  while (done < buffered_) {
    const ssize_t wrote = ::pwrite(fd_, buffer_.data() + done, buffered_ - done, off_t(file_offset_ + done));
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) {
      throw SpillError(fmt::format("reorder.spill_dir = {}: writing {} bytes of rays failed: {}", directory_,
                                   buffered_ - done, wrote < 0 ? std::strerror(errno) : "no space written"));
    }
    done += std::size_t(wrote);
  }
  file_offset_ += buffered_;
  counters_.bytes_written += buffered_;
  buffered_ = 0;
}

void SpillRun::write_bytes(const void* data, std::size_t bytes) {
  const auto* from = static_cast<const std::byte*>(data);
  while (bytes > 0) {
    const std::size_t part = std::min(bytes, buffer_.size() - buffered_);
    std::memcpy(buffer_.data() + buffered_, from, part);
    buffered_ += part;
    from += part;
    bytes -= part;
    if (buffered_ == buffer_.size()) flush_writes();
  }
}

void SpillRun::append(RayBatch& rays) {
  // A spilled ray has its key: its approximate hit, which only made the key, stays behind
  // (a batch from the pool may still hold a stale one).
  const BlockHeader header{std::uint32_t(rays.count), rays.has_sort_key() ? kSortKeyColumns : 0u};
  write_bytes(&header, sizeof header);
  rays.for_each_column([&](const char*, void* column, std::size_t element_bytes) {
    write_bytes(column, rays.count * element_bytes);
  }, /*with_approx_hit=*/false, rays.has_sort_key());
  rays_ += rays.count;
}

void SpillRun::finish_writing() {
  flush_writes();
  file_bytes_ = file_offset_;
  file_offset_ = 0;
  buffered_ = consumed_ = 0;
}

void SpillRun::read_bytes(void* data, std::size_t bytes) {
  auto* to = static_cast<std::byte*>(data);
  while (bytes > 0) {
    if (consumed_ == buffered_) {
      Timer timer(counters_.seconds);
      const std::size_t want = std::min<std::uint64_t>(buffer_.size(), file_bytes_ - file_offset_);
      if (want == 0) throw SpillError(fmt::format("reorder.spill_dir = {}: a spill run ended early", directory_));
      ssize_t got = 0;
      do {
        got = ::pread(fd_, buffer_.data(), want, off_t(file_offset_));
      } while (got < 0 && errno == EINTR);
      if (got <= 0) {
        throw SpillError(fmt::format("reorder.spill_dir = {}: reading rays back failed: {}", directory_,
                                     got < 0 ? std::strerror(errno) : "short read"));
      }
      file_offset_ += std::uint64_t(got);
      counters_.bytes_read += std::uint64_t(got);
      buffered_ = std::size_t(got);
      consumed_ = 0;
    }
    const std::size_t part = std::min(bytes, buffered_ - consumed_);
    std::memcpy(to, buffer_.data() + consumed_, part);
    consumed_ += part;
    to += part;
    bytes -= part;
  }
}

bool SpillRun::read_block(RayBatch& rays) {
  if (file_offset_ == file_bytes_ && consumed_ == buffered_) return false;
  BlockHeader header{};
  read_bytes(&header, sizeof header);
  if (header.count == 0 || header.count > rays.capacity()) {
    throw SpillError(fmt::format("reorder.spill_dir = {}: a spill block holds {} rays, not 1 to {}", directory_,
                                 header.count, rays.capacity()));
  }
  if ((header.columns & ~kSortKeyColumns) != 0) {
    throw SpillError(fmt::format("reorder.spill_dir = {}: a spill block names columns {:#x}, not a run's", directory_,
                                 header.columns));
  }
  const bool sort_key = header.columns & kSortKeyColumns;
  if (sort_key) rays.enable_sort_key();
  rays.count = header.count;
  rays.for_each_column(
      [&](const char*, void* column, std::size_t element_bytes) { read_bytes(column, rays.count * element_bytes); },
      /*with_approx_hit=*/false, sort_key);
  return true;
}

}  // namespace wavetrace
