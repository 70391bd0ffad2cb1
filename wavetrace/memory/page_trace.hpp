// The pages a paged render announced, in the order it announced them, written to a file for
// replacement policies to be studied offline (bench/page_policies.py: LRU against Belady's
// optimum on the same sequence), so that what a better pool could buy is measured, not guessed.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace wavetrace {

// File format: a flat sequence of little-endian uint32, one per touch, each the file page
// (byte offset / memory.page_bytes) a probe announced before a read; no header. A thread's
// reads of the page it touched last are not touches, so consecutive repeats are rare. With
// several threads the order is the one in which their touches took the trace's lock.
class PageTrace {
 public:
  // Creates or truncates `path`; throws std::runtime_error naming it when it cannot.
  explicit PageTrace(std::string path);
  ~PageTrace();  // writes what is buffered; a failure then is reported on stderr
  PageTrace(const PageTrace&) = delete;
  PageTrace& operator=(const PageTrace&) = delete;

  // Thread-safe. Throws std::runtime_error naming the file when a write fails (disk full).
  void record(std::uint32_t page);
  // Writes what is buffered; throws as record does.
  void flush();
  std::uint64_t recorded() const;
  const std::string& path() const { return path_; }

 private:
  void flush_locked();

  std::string path_;
  int fd_ = -1;
  mutable std::mutex mutex_;
  std::vector<std::uint32_t> buffer_;  // written at 1 Mi entries (4 MiB)
  std::uint64_t recorded_ = 0;
};

}  // namespace wavetrace
