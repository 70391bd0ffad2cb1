// Section file writing: sequential pwrite of each section, table and header last.
#include "wavetrace/memory/section_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <utility>

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <fmt/format.h>

namespace wavetrace {

using namespace section_file;

namespace {

std::uint64_t align_up_u64(std::uint64_t value, std::uint64_t alignment) { return (value + alignment - 1) / alignment * alignment; }

}  // namespace

SectionWriter::SectionWriter(std::string path)
    : path_(std::move(path)), partial_path_(fmt::format("{}.{}.partial", path_, ::getpid())) {
  // Found now, not by the rename after a build of hours.
  if (std::error_code error; std::filesystem::is_directory(path_, error)) {
    throw std::runtime_error(fmt::format("{}: cannot create: it is a directory", path_));
  }
  const std::filesystem::path parent = std::filesystem::path(path_).parent_path();
  const std::string directory = parent.empty() ? std::string(".") : parent.string();
  fd_ = ::open(directory.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
  unnamed_ = fd_ >= 0;
  // EISDIR: a kernel without O_TMPFILE; EOPNOTSUPP: a file system without it.
  if (fd_ < 0 && (errno == EOPNOTSUPP || errno == EISDIR)) {
    fd_ = ::open(partial_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  }
  if (fd_ < 0) throw std::runtime_error(fmt::format("{}: cannot create: {}", path_, std::strerror(errno)));
  // The header stays zero until finish(): a file cut short by a crash reads as "not a world".
  const Header zero{};
  write_at(0, &zero, sizeof(zero));
  position_ = kDataAlignment;
}

SectionWriter::~SectionWriter() {
  if (fd_ < 0) return;
  ::close(fd_);
  if (!unnamed_) ::unlink(partial_path_.c_str());
}

void SectionWriter::write_at(std::uint64_t offset, const void* data, std::size_t bytes) {
  const auto* cursor = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t written = ::pwrite(fd_, cursor, std::min<std::size_t>(bytes, std::size_t{1} << 30), off_t(offset));
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) throw std::runtime_error(fmt::format("{}: write failed: {}", path_, std::strerror(errno)));
    cursor += written;
    offset += std::uint64_t(written);
    bytes -= std::size_t(written);
  }
}

void SectionWriter::add(std::string_view name, std::span<const std::byte> bytes, std::uint32_t element_bytes) {
  if (fd_ < 0) throw std::logic_error(fmt::format("{}: section '{}' added after finish()", path_, name));
  if (name.empty() || name.size() >= kNameBytes) {
    throw std::invalid_argument(fmt::format("section name '{}': must be 1 to {} bytes", name, kNameBytes - 1));
  }
  if (!names_.emplace(name).second) throw std::invalid_argument(fmt::format("section '{}' added twice", name));
  TableEntry entry{};
  std::memcpy(entry.name, name.data(), name.size());
  entry.offset = position_;
  entry.size = bytes.size();
  entry.checksum = XXH3_64bits(bytes.data(), bytes.size());
  entry.element_bytes = element_bytes;
  write_at(position_, bytes.data(), bytes.size());
  position_ = align_up_u64(position_ + bytes.size(), kDataAlignment);
  table_.push_back(entry);
}

void SectionWriter::finish() {
  std::sort(table_.begin(), table_.end(),
            [](const TableEntry& a, const TableEntry& b) { return std::strncmp(a.name, b.name, kNameBytes) < 0; });
  Header header{};
  std::memcpy(header.magic, kMagic, sizeof(kMagic));
  header.version = kSectionFileVersion;
  header.section_count = static_cast<std::uint32_t>(table_.size());
  header.table_offset = position_;
  const std::size_t table_bytes = table_.size() * sizeof(TableEntry);
  header.file_size = align_up_u64(position_ + table_bytes, kDataAlignment);
  header.table_checksum = XXH3_64bits(table_.data(), table_bytes);
  header.header_checksum = XXH3_64bits(&header, kHeaderChecksummedBytes);
  write_at(position_, table_.data(), table_bytes);
  if (::ftruncate(fd_, off_t(header.file_size)) != 0) {
    throw std::runtime_error(fmt::format("{}: cannot set its size: {}", path_, std::strerror(errno)));
  }
  write_at(0, &header, sizeof(header));
  const auto fail = [&](std::string_view what, int error) {
    throw std::runtime_error(fmt::format("{}: {} failed: {}", path_, what, std::strerror(error)));
  };
  if (unnamed_) {
    ::unlink(partial_path_.c_str());  // what a crashed writer of the same process id left there
    // The documented way to name an O_TMPFILE file without CAP_DAC_READ_SEARCH (open(2)); a
    // process without /proc but with that capability (root) names it through the descriptor.
    const std::string self = fmt::format("/proc/self/fd/{}", fd_);
    if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, partial_path_.c_str(), AT_SYMLINK_FOLLOW) != 0 &&
        ::linkat(fd_, "", AT_FDCWD, partial_path_.c_str(), AT_EMPTY_PATH) != 0) {
      const int error = errno;
      ::close(std::exchange(fd_, -1));
      fail(fmt::format("naming the written file {}", partial_path_), error);
    }
  }
  if (::close(std::exchange(fd_, -1)) != 0 || ::rename(partial_path_.c_str(), path_.c_str()) != 0) {
    const int error = errno;
    ::unlink(partial_path_.c_str());
    fail(fmt::format("closing and renaming {}", partial_path_), error);
  }
}

}  // namespace wavetrace
