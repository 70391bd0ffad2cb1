// The on-disk part of a ray buffer (the reordering paper, §4 "Ray buffer"): runs of rays
// sorted by key, written and read back in large sequential blocks. A run lives in an unnamed
// file (O_TMPFILE) in the spill directory, so the kernel frees it when the run is closed or
// the process ends in any way (an error, SIGINT, SIGTERM, a crash): no spill file outlives
// the render.
//
// Run format, one block per batch of rays, blocks back to back from offset 0 (native
// little-endian x86-64, no padding):
//   offset 0   u32  count: rays in the block (1 .. the writer's batch capacity)
//          4   u32  columns: bit 1 set when the sort key column follows (zsort's runs have
//                   it); no other bit is set (a keyed ray's approximate hit stays behind)
//          8        the ray columns of RayBatch::for_each_column in its order (origin_x ...
//                   flags), then sort_key when present, count x the column's
//                   element bytes (4, or 2 for depth, 1 for kind and flags, 8 for sort_key)
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

class SpillError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads and writes of the runs a buffer made, for its statistics.
struct SpillCounters {
  std::uint64_t bytes_written = 0;
  std::uint64_t bytes_read = 0;
  double seconds = 0.0;  // in reads and writes
  std::uint64_t runs = 0;
};

// Bytes free on the file system of `directory`; throws SpillError naming it when it is not a
// directory this process can create spill files in.
std::uint64_t spill_directory_free_bytes(const std::string& directory);

// One run: written once from sorted batches, then read back from its start, block by block.
class SpillRun {
 public:
  // Creates the run's unnamed file in `directory`; throws SpillError naming the directory.
  SpillRun(const std::string& directory, SpillCounters& counters);
  ~SpillRun();
  SpillRun(const SpillRun&) = delete;
  SpillRun& operator=(const SpillRun&) = delete;

  // Appends the batch's rays (their columns and key, not an approximate hit) as one block.
  void append(RayBatch& rays);
  // Ends writing (flushes what is buffered); reading starts at the first block.
  void finish_writing();
  // The next block into `rays` (count and columns; the optional columns enabled as the block
  // says); false at the end of the run.
  bool read_block(RayBatch& rays);
  std::uint64_t rays() const { return rays_; }

 private:
  void write_bytes(const void* data, std::size_t bytes);
  void flush_writes();
  void read_bytes(void* data, std::size_t bytes);

  std::string directory_;
  SpillCounters& counters_;
  int fd_ = -1;
  std::vector<std::byte> buffer_;  // large sequential reads and writes (1 MiB)
  std::size_t buffered_ = 0, consumed_ = 0;
  std::uint64_t file_offset_ = 0, file_bytes_ = 0, rays_ = 0;
};

}  // namespace wavetrace
