// Buffered appends of page numbers under one lock; a render's touches come a few per ray, so
// the lock is taken only while a trace is asked for (memory.page_trace).
#include "wavetrace/memory/page_trace.hpp"

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>

namespace wavetrace {

static_assert(std::endian::native == std::endian::little, "page traces are written little-endian as they lie");

namespace {
constexpr std::size_t kBufferEntries = std::size_t{1} << 20;
}

PageTrace::PageTrace(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw std::runtime_error(fmt::format("memory.page_trace: cannot write '{}': {}", path_, std::strerror(errno)));
  }
  buffer_.reserve(kBufferEntries);
}

PageTrace::~PageTrace() {
  try {
    flush();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "wavetrace: %s\n", error.what());
  }
  ::close(fd_);
}

void PageTrace::record(std::uint32_t page) {
  std::lock_guard lock(mutex_);
  buffer_.push_back(page);
  ++recorded_;
  if (buffer_.size() == kBufferEntries) flush_locked();
}

void PageTrace::flush() {
  std::lock_guard lock(mutex_);
  flush_locked();
}

std::uint64_t PageTrace::recorded() const {
  std::lock_guard lock(mutex_);
  return recorded_;
}

void PageTrace::flush_locked() {
  const auto* bytes = reinterpret_cast<const char*>(buffer_.data());
  const std::size_t total = buffer_.size() * sizeof(std::uint32_t);
  for (std::size_t done = 0; done < total;) {
    const ssize_t wrote = ::write(fd_, bytes + done, total - done);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) {
      buffer_.clear();  // not written again by the destructor
      throw std::runtime_error(fmt::format("memory.page_trace: writing '{}' failed: {}", path_,
                                           wrote < 0 ? std::strerror(errno) : "no progress"));
    }
    done += std::size_t(wrote);
  }
  buffer_.clear();
}

}  // namespace wavetrace
