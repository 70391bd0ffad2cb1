// Section file reading: every check the format allows, before anything is handed out.
#include "wavetrace/memory/section_file.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/memory/process_memory.hpp"

namespace wavetrace {

using namespace section_file;
static_assert(std::endian::native == std::endian::little, "section files are little-endian and used in place");

namespace {

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

bool read_exactly(int fd, void* data, std::size_t bytes, std::uint64_t offset) {
  auto* cursor = static_cast<char*>(data);
  while (bytes > 0) {
    const ssize_t got = ::pread(fd, cursor, bytes, off_t(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    cursor += got;
    offset += std::uint64_t(got);
    bytes -= std::size_t(got);
  }
  return true;
}

// The checksum of a section read through a small buffer (4 KiB-aligned for an O_DIRECT `fd`:
// verifying a paged world neither fills the page cache nor holds more than the buffer).
std::uint64_t checksum_by_reads(int fd, std::uint64_t offset, std::uint64_t size, std::byte* buffer, std::size_t buffer_bytes) {
  XXH3_state_t* state = XXH3_createState();
  XXH3_64bits_reset(state);
  for (std::uint64_t done = 0; done < size;) {
    const std::size_t piece = static_cast<std::size_t>(std::min<std::uint64_t>(buffer_bytes, size - done));
    const std::size_t request = (piece + 4095) / 4096 * 4096;
    std::size_t got = 0;
    while (got < piece) {
      const ssize_t n = ::pread(fd, buffer + got, request - got, off_t(offset + done + got));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += std::size_t(n);
    }
    if (got < piece) {
      XXH3_freeState(state);
      return ~XXH3_64bits(nullptr, 0);  // a short read can never match
    }
    XXH3_64bits_update(state, buffer, piece);
    done += piece;
  }
  const std::uint64_t sum = XXH3_64bits_digest(state);
  XXH3_freeState(state);
  return sum;
}

// The checksum of a section read into its place in a copy of the file, a piece at a time so
// that each piece is summed while it is still in the cache.
std::uint64_t checksum_by_copy(int fd, std::uint64_t offset, std::uint64_t size, std::byte* destination) {
  constexpr std::size_t kPieceBytes = std::size_t{512} << 10;
  XXH3_state_t* state = XXH3_createState();
  XXH3_64bits_reset(state);
  for (std::uint64_t done = 0; done < size;) {
    const std::size_t piece = static_cast<std::size_t>(std::min<std::uint64_t>(kPieceBytes, size - done));
    if (!read_exactly(fd, destination + done, piece, offset + done)) {
      XXH3_freeState(state);
      return ~XXH3_64bits(nullptr, 0);  // a short read can never match
    }
    XXH3_64bits_update(state, destination + done, piece);
    done += piece;
  }
  const std::uint64_t sum = XXH3_64bits_digest(state);
  XXH3_freeState(state);
  return sum;
}

}  // namespace

std::string_view to_string(FileHolding holding) { return holding == FileHolding::copied ? "copied" : "mapped"; }

void SectionFile::fail(std::string_view section, const std::string& problem) const {
  if (section.empty()) throw SectionFileError(fmt::format("{}: {}", path_, problem));
  throw SectionFileError(fmt::format("{}: section '{}' {}", path_, section, problem));
}

std::shared_ptr<const SectionFile> SectionFile::open(const std::string& path, const std::optional<PagingRequest>& paging,
                                                     CheckedPages checked, FileHolding holding) {
  std::shared_ptr<SectionFile> file(new SectionFile());
  file->path_ = path;
  file->checked_ = checked;
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) file->fail({}, fmt::format("cannot open: {}", std::strerror(errno)));
  struct stat status {};
  if (::fstat(fd.get(), &status) != 0 || !S_ISREG(status.st_mode)) file->fail({}, "not a regular file");
  const auto actual_size = std::uint64_t(status.st_size);

  Header header{};
  if (actual_size < sizeof(Header) || !read_exactly(fd.get(), &header, sizeof(header), 0)) {
    file->fail({}, fmt::format("truncated: {} bytes, less than a world file's {}-byte header", actual_size, sizeof(Header)));
  }
  const Header zero{};
  if (std::memcmp(&header, &zero, sizeof(header)) == 0) {
    file->fail({}, "incomplete: its header was never written (a save that did not finish?)");
  }
  if (std::memcmp(header.magic, kMagic, sizeof(kMagic)) != 0) {
    file->fail({}, "not a wavetrace world file (wrong magic; worlds are made by `wavetrace build`)");
  }
  if (header.header_checksum != XXH3_64bits(&header, kHeaderChecksummedBytes)) file->fail({}, "header checksum mismatch");
  if (header.version != kSectionFileVersion) {
    file->fail({}, fmt::format("container version {}; this build reads version {} (rebuild the world)", header.version,
                               kSectionFileVersion));
  }
  if (actual_size != header.file_size) {
    file->fail({}, fmt::format("{}: {} bytes where its header says {}", actual_size < header.file_size ? "truncated" : "too long",
                               actual_size, header.file_size));
  }
  const std::uint64_t table_bytes = std::uint64_t(header.section_count) * sizeof(TableEntry);
  if (header.table_offset < kDataAlignment || header.table_offset % 8 != 0 || header.table_offset > actual_size ||
      table_bytes > actual_size - header.table_offset) {
    file->fail({}, fmt::format("its table ({} sections at byte {}) lies outside the file", header.section_count,
                               header.table_offset));
  }
  std::vector<TableEntry> table(header.section_count);
  if (!read_exactly(fd.get(), table.data(), table_bytes, header.table_offset)) file->fail({}, "cannot read its table");
  if (header.table_checksum != XXH3_64bits(table.data(), table_bytes)) file->fail({}, "table checksum mismatch");

  std::vector<std::pair<std::uint64_t, std::uint64_t>> extents;
  for (const TableEntry& entry : table) {
    if (std::find(entry.name, entry.name + kNameBytes, '\0') == entry.name + kNameBytes || entry.name[0] == '\0') {
      file->fail({}, "a section name is not terminated");
    }
    const std::string name = entry.name;
    if (entry.offset % kDataAlignment != 0 || entry.offset < kDataAlignment || entry.offset > header.table_offset ||
        entry.size > header.table_offset - entry.offset) {
      file->fail(name, fmt::format("lies outside the file's data (bytes {}..{} of {})", entry.offset,
                                   entry.offset + entry.size, header.table_offset));
    }
    if (entry.element_bytes == 0 || entry.size % entry.element_bytes != 0) {
      file->fail(name, fmt::format("is {} bytes, no whole number of {}-byte elements", entry.size, entry.element_bytes));
    }
    if (!file->sections_.empty() && file->sections_.back().name >= name) file->fail(name, "is out of order or repeated");
    file->sections_.push_back({name, entry.offset, entry.size, entry.element_bytes});
    extents.emplace_back(entry.offset, entry.size);
  }
  std::sort(extents.begin(), extents.end());
  for (std::size_t i = 1; i < extents.size(); ++i) {
    if (extents[i - 1].first + extents[i - 1].second > extents[i].first) file->fail({}, "two sections overlap");
  }
  file->file_bytes_ = actual_size;

  const auto verify_start = std::chrono::steady_clock::now();
  std::vector<std::uint64_t> sums(table.size());
  if (paging) {
    const FileDescriptor direct(::open(path.c_str(), O_RDONLY | O_DIRECT | O_CLOEXEC));
    if (direct.get() < 0) file->fail({}, fmt::format("cannot open for direct reads: {}", std::strerror(errno)));
    constexpr std::size_t kBufferBytes = std::size_t{8} << 20;
    std::unique_ptr<std::byte, decltype(&std::free)> buffer(static_cast<std::byte*>(std::aligned_alloc(4096, kBufferBytes)),
                                                           &std::free);
    for (std::size_t i = 0; i < table.size(); ++i) {
      sums[i] = checksum_by_reads(direct.get(), table[i].offset, table[i].size, buffer.get(), kBufferBytes);
    }
    try {
      const std::size_t budget_bytes =
          paging->budget.is_share ? static_cast<std::size_t>(std::ceil(paging->budget.share * double(actual_size)))
                                  : paging->budget.bytes;
      file->pager_ = std::make_unique<FilePager>(path, actual_size, paging->page_bytes, budget_bytes, paging->clients,
                                                paging->mapping);
    } catch (const std::exception& error) {
      throw SectionFileError(error.what());
    }
    file->base_ = file->pager_->base();
    file->name_paged_parts();
  } else {
    if (holding == FileHolding::copied) {
      const std::size_t available = available_memory_bytes();
      const std::uint64_t needed = actual_size + kCopyReserveBytes;
      if (checked == CheckedPages::given_back) {
        file->holding_note_ = "mapped, not copied: a data-parallel rank holds only the chunks it answers";
      } else if (available < needed) {
        file->holding_note_ = fmt::format(
            "mapped, not copied: a copy needs {:.2f} GB (the file and a reserve of {:.0f} GB), the machine has {:.2f} GB "
            "available",
            double(needed) * 1e-9, double(kCopyReserveBytes) * 1e-9, double(available) * 1e-9);
      } else {
        // On a 2 MiB boundary whatever its size: sections keep the 4 KiB alignment the format
        // promises, and a large file starts on a huge page.
        const std::size_t bytes = align_up(static_cast<std::size_t>(actual_size), kHugePageBytes);
        file->copy_ = std::aligned_alloc(kHugePageBytes, bytes);
        if (file->copy_ == nullptr) file->fail({}, fmt::format("cannot be copied: {} bytes could not be allocated", bytes));
        if (huge_pages_advised()) ::madvise(file->copy_, bytes, MADV_HUGEPAGE);  // advice only: failure is harmless
        auto* copy = static_cast<std::byte*>(file->copy_);
        tbb::parallel_for(std::size_t{0}, table.size(), [&](std::size_t i) {
          sums[i] = checksum_by_copy(fd.get(), table[i].offset, table[i].size, copy + table[i].offset);
        });
        file->base_ = copy;
      }
    }
    if (file->copy_ == nullptr) {
      void* mapping = ::mmap(nullptr, actual_size, PROT_READ, MAP_SHARED, fd.get(), 0);
      if (mapping == MAP_FAILED) file->fail({}, fmt::format("cannot be mapped: {}", std::strerror(errno)));
      file->mapping_ = mapping;
      file->base_ = static_cast<const std::byte*>(mapping);
      // Read, not through the mapping: checking a page must not make it resident in this
      // process, which then holds only what its render touches (a data-parallel rank its own
      // chunks; docs/distributed.md). The page cache keeps what was read for the mapping.
      tbb::parallel_for(std::size_t{0}, table.size(), [&](std::size_t i) {
        constexpr std::size_t kBufferBytes = std::size_t{1} << 20;
        const std::unique_ptr<std::byte[]> buffer(new std::byte[kBufferBytes]);
        sums[i] = checksum_by_reads(fd.get(), table[i].offset, table[i].size, buffer.get(), kBufferBytes);
      });
    }
  }
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (sums[i] != table[i].checksum) file->fail(table[i].name, "checksum mismatch: the file is damaged");
  }
  file->verify_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - verify_start).count();
  return file;
}

void SectionFile::name_paged_parts() {
  // A part is a section's name with its chunk number dropped ("accel/chunk.17/hmq8.nodes" is
  // part "accel/chunk.*/hmq8.nodes"): the reads of every chunk's nodes count together.
  const auto part_name = [](const std::string& name) {
    std::string part;
    for (std::size_t at = 0; at < name.size();) {
      std::size_t digits = name.compare(at, 6, "chunk.") == 0 ? at + 6 : at;
      while (digits > at && digits < name.size() && name[digits] >= '0' && name[digits] <= '9') ++digits;
      if (digits > at + 6 && digits < name.size() && name[digits] == '/') {
        part += "chunk.*";
        at = digits;
      } else {
        part += name[at++];
      }
    }
    return part;
  };
  std::vector<std::string> names;
  std::vector<FilePart> extents;
  for (const SectionInfo& section : sections_) {
    const std::string name = part_name(section.name);
    auto known = std::find(names.begin(), names.end(), name);
    if (known == names.end()) known = names.insert(names.end(), name);
    // A section owns its padding up to the next 4 KiB: reads never land there, pages may.
    const std::uint64_t bytes = (section.size + kDataAlignment - 1) / kDataAlignment * kDataAlignment;
    extents.push_back({section.offset, bytes, static_cast<std::uint32_t>(known - names.begin())});
  }
  pager_->name_parts(std::move(names), std::move(extents));
}

SectionFile::~SectionFile() {
  if (mapping_ != nullptr) ::munmap(mapping_, file_bytes_);
  std::free(copy_);
}

const SectionInfo* SectionFile::find(std::string_view name) const {
  const auto it = std::lower_bound(sections_.begin(), sections_.end(), name,
                                   [](const SectionInfo& info, std::string_view key) { return info.name < key; });
  return it != sections_.end() && it->name == name ? &*it : nullptr;
}

bool SectionFile::has(std::string_view name) const { return find(name) != nullptr; }

std::span<const std::byte> SectionFile::bytes(std::string_view name) const {
  const SectionInfo* info = find(name);
  if (info == nullptr) fail(name, "is missing");
  return {base_ + info->offset, static_cast<std::size_t>(info->size)};
}

std::span<const std::byte> SectionFile::checked(std::string_view name, std::size_t element_bytes) const {
  const SectionInfo* info = find(name);
  if (info == nullptr) fail(name, "is missing");
  if (info->element_bytes != element_bytes) {
    fail(name, fmt::format("holds {}-byte elements where {}-byte ones were expected", info->element_bytes, element_bytes));
  }
  return {base_ + info->offset, static_cast<std::size_t>(info->size)};
}

void SectionFile::drop_resident_pages() const {
  if (mapping_ != nullptr) ::madvise(mapping_, file_bytes_, MADV_DONTNEED);
}

}  // namespace wavetrace
