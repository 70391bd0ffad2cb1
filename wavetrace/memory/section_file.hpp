// A section file opened for use in place: its header, table and every section's checksum
// checked first, then its sections handed out as spans: of a read-only mapping (the OS pages
// it), of a copy on huge pages, or of a FilePager's range (real paging under a budget). Every
// problem is a SectionFileError naming the file and what is wrong with it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "wavetrace/memory/file_pager.hpp"
#include "wavetrace/memory/memory_budget.hpp"
#include "wavetrace/memory/section_file_format.hpp"

namespace wavetrace {

class SectionFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SectionInfo {
  std::string name;
  std::uint64_t offset = 0, size = 0;
  std::uint32_t element_bytes = 1;
};

// What the loaders' checks of a mapped file leave resident: every page they touched, as a
// render of the whole world wants; or, for a process that answers for a part of a chunked world
// (a data-parallel rank), nothing past each chunk: a chunked world's loader gives the pages back
// as each chunk is checked (chunk_checked), so the load never holds the whole world at once.
enum class CheckedPages { kept, given_back };

// How a file that is not paged under a budget is held.
// - mapped: read-only and shared; the OS reads a page in when it is first touched, on 4 KiB
//   pages, and the process holds only what its render touches.
// - copied: read whole into anonymous memory advised onto 2 MiB pages. A walk over a world of
//   gigabytes misses the TLB at nearly every node on 4 KiB pages, and the page tables of a
//   9.5 GB world (19 MB of entries) do not stay in the caches beside the nodes; on 2 MiB pages
//   they are 512 times fewer. Taken only where the machine can spare the memory (MemAvailable
//   at least the file plus kCopyReserveBytes) and the whole world is wanted (not by a
//   data-parallel rank, CheckedPages::given_back); the file is mapped otherwise, and
//   holding_note() says why.
enum class FileHolding { mapped, copied };
inline constexpr std::size_t kCopyReserveBytes = std::size_t{1} << 30;
std::string_view to_string(FileHolding holding);

class SectionFile {
 public:
  // With `paging` its pages are read on demand into a pool of the budget's size; without it
  // the file is held whole as `holding` asks (and the machine allows). Throws SectionFileError.
  static std::shared_ptr<const SectionFile> open(const std::string& path,
                                                 const std::optional<PagingRequest>& paging = std::nullopt,
                                                 CheckedPages checked = CheckedPages::kept,
                                                 FileHolding holding = FileHolding::mapped);
  ~SectionFile();
  SectionFile(const SectionFile&) = delete;
  SectionFile& operator=(const SectionFile&) = delete;

  const std::string& path() const { return path_; }
  std::uint64_t file_bytes() const { return file_bytes_; }
  const std::vector<SectionInfo>& sections() const { return sections_; }
  bool has(std::string_view name) const;
  double verify_seconds() const { return verify_seconds_; }
  // A mapped file: gives back the pages this process has touched (they stay in the page
  // cache), so that from now on it holds only what it reads again. No-op when paged.
  void drop_resident_pages() const;
  // Called by a chunked world's loader after each chunk: drop_resident_pages when the file was
  // opened with CheckedPages::given_back, nothing otherwise.
  void chunk_checked() const {
    if (checked_ == CheckedPages::given_back) drop_resident_pages();
  }
  // The real pager, when the file is paged; null when it is held whole.
  FilePager* pager() const { return pager_.get(); }
  // How a file held whole is held (mapped for a paged file), and why a copy that was asked
  // for was not made (empty when it was, or none was asked for).
  FileHolding holding() const { return copy_ != nullptr ? FileHolding::copied : FileHolding::mapped; }
  const std::string& holding_note() const { return holding_note_; }

  // A section's bytes in place; throws SectionFileError when it is missing.
  std::span<const std::byte> bytes(std::string_view name) const;
  // A section as an array of T: its element size must be sizeof(T).
  template <typename T>
  std::span<const T> array(std::string_view name) const {
    const std::span<const std::byte> raw = checked(name, sizeof(T));
    return {reinterpret_cast<const T*>(raw.data()), raw.size() / sizeof(T)};
  }
  // A section holding exactly one T, copied out.
  template <typename T>
  T value(std::string_view name) const {
    const std::span<const T> items = array<T>(name);
    if (items.size() != 1) fail(name, "holds " + std::to_string(items.size()) + " values where one was expected");
    return items[0];
  }
  [[noreturn]] void fail(std::string_view section, const std::string& problem) const;

 private:
  // Tells the pager which sections its pages belong to, so faults are counted by part.
  void name_paged_parts();
  SectionFile() = default;
  std::span<const std::byte> checked(std::string_view name, std::size_t element_bytes) const;
  const SectionInfo* find(std::string_view name) const;

  std::string path_;
  std::uint64_t file_bytes_ = 0;
  std::vector<SectionInfo> sections_;  // sorted by name
  const std::byte* base_ = nullptr;
  void* mapping_ = nullptr;  // the whole-file mapping, when mapped
  void* copy_ = nullptr;     // the whole file on huge pages, when copied
  std::string holding_note_;
  std::unique_ptr<FilePager> pager_;
  double verify_seconds_ = 0.0;
  CheckedPages checked_ = CheckedPages::kept;
};

}  // namespace wavetrace
