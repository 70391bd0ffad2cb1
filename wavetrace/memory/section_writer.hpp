// Writes a section file (section_file_format.hpp) front to back: each section's bytes go
// to the file as they are added, with their checksum, so a saved world never needs a
// second copy of itself in memory (a chunked world is written chunk by chunk while it is
// built, ChunkStream); the table and header are written by finish(). The bytes go to an
// unnamed file (O_TMPFILE) in `path`'s directory, given a name and renamed over `path` by
// finish(): a build that fails keeps the world that was at `path` before, a process that has
// that world mapped keeps reading it (truncating it in place would fault its pages), and a
// build that ends any other way (an error, SIGINT, SIGTERM, SIGKILL, a crash) leaves nothing
// behind: a world of tens of gigabytes left half written would only fill the disk. Where the
// file system has no O_TMPFILE, the file is named "PATH.PID.partial" from the start and
// removed by the destructor instead.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_set>
#include <vector>

#include "wavetrace/memory/section_file_format.hpp"

namespace wavetrace {

class SectionWriter {
 public:
  // Creates the unnamed file in `path`'s directory; throws std::runtime_error naming `path`
  // when it cannot.
  explicit SectionWriter(std::string path);
  ~SectionWriter();
  SectionWriter(const SectionWriter&) = delete;
  SectionWriter& operator=(const SectionWriter&) = delete;

  // Adds a section; names are unique and at most 63 bytes (std::invalid_argument otherwise).
  // Any order: the table is sorted by name when finished.
  void add(std::string_view name, std::span<const std::byte> bytes, std::uint32_t element_bytes = 1);
  template <typename T>
  void add_array(std::string_view name, std::span<const T> items) {
    static_assert(std::is_trivially_copyable_v<T>);
    add(name, std::as_bytes(items), sizeof(T));
  }
  template <typename T>
  void add_value(std::string_view name, const T& value) {
    add_array(name, std::span<const T>(&value, 1));
  }

  // Writes the table and header, links the file as "PATH.PID.partial" and renames that over
  // `path`. Until then the file is not valid (its header is zero), so a named partial file
  // left by a crash is refused when read.
  void finish();

  // The name the file has before it becomes `path`: from the start where the file system
  // has no O_TMPFILE, only inside finish() otherwise.
  const std::string& partial_path() const { return partial_path_; }
  bool unnamed() const { return unnamed_; }

 private:
  void write_at(std::uint64_t offset, const void* data, std::size_t bytes);

  std::string path_, partial_path_;
  int fd_ = -1;
  bool unnamed_ = false;
  std::uint64_t position_ = 0;
  std::vector<section_file::TableEntry> table_;
  std::unordered_set<std::string> names_;  // builtin:room:3G's world has 3,630 sections
};

}  // namespace wavetrace
