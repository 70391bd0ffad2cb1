// One list of an accelerator's saved parts serves both directions: an accelerator writes
// `template <typename Archive> static void archive(auto& self, Archive& a)` naming each
// array and value once, and SectionSaver writes them to a world file while SectionLoader
// points them into a mapped one (nothing copied but the small values).
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>

#include "wavetrace/memory/section_file.hpp"
#include "wavetrace/memory/section_writer.hpp"
#include "wavetrace/memory/stored_array.hpp"

namespace wavetrace {

// The first section of every saved accelerator, `PREFIX` + "kind" (24 bytes):
//   offset  size  field
//        0    16  type: the accelerator's name (accelerator_names()), NUL-padded ASCII
//       16     4  format version of that accelerator's saved sections
//       20     4  zero
struct SavedKind {
  char type[16];
  std::uint32_t version;
  std::uint32_t zero;
};
static_assert(sizeof(SavedKind) == 24);

inline SavedKind saved_kind(std::string_view type, std::uint32_t version) {
  SavedKind kind{};
  std::memcpy(kind.type, type.data(), std::min(type.size(), sizeof(kind.type) - 1));
  kind.version = version;
  return kind;
}

class SectionSaver {
 public:
  SectionSaver(SectionWriter& out, std::string prefix) : out_(out), prefix_(std::move(prefix)) {}
  static constexpr bool kLoading = false;
  template <typename T>
  void array(std::string_view name, const StoredArray<T>& items) {
    out_.add_array<T>(named(name), items.span());
  }
  template <typename T>
  void value(std::string_view name, const T& item) {
    out_.add_value(named(name), item);
  }
  const std::string& prefix() const { return prefix_; }
  SectionWriter& writer() const { return out_; }

 private:
  // prefix + name, appended rather than `prefix_ + std::string(name)`, whose inlined insert
  // GCC 12 misreads as an overlapping memcpy (-Wrestrict, GCC bug 105651).
  std::string named(std::string_view name) const { return std::string(prefix_).append(name); }
  SectionWriter& out_;
  std::string prefix_;
};

class SectionLoader {
 public:
  SectionLoader(std::shared_ptr<const SectionFile> file, std::string prefix)
      : file_(std::move(file)), prefix_(std::move(prefix)) {}
  static constexpr bool kLoading = true;
  template <typename T>
  void array(std::string_view name, StoredArray<T>& items) {
    items = StoredArray<T>(file_->array<T>(named(name)), file_);
  }
  template <typename T>
  void value(std::string_view name, T& item) {
    item = file_->value<T>(named(name));
  }
  // Checks the saved kind against what this build writes; throws SectionFileError.
  void expect_kind(std::string_view type, std::uint32_t version) const {
    const SavedKind kind = file_->value<SavedKind>(prefix_ + "kind");
    const std::string saved(kind.type, strnlen(kind.type, sizeof(kind.type)));
    if (saved != type) file_->fail(prefix_ + "kind", fmt::format("is a '{}' accelerator where '{}' was expected", saved, type));
    if (kind.version != version) {
      file_->fail(prefix_ + "kind", fmt::format("holds '{}' format version {}; this build reads version {} (rebuild the world)",
                                                type, kind.version, version));
    }
  }
  [[noreturn]] void fail(std::string_view name, const std::string& problem) const {
    file_->fail(named(name), problem);
  }
  bool has(std::string_view name) const { return file_->has(named(name)); }
  const std::shared_ptr<const SectionFile>& file() const { return file_; }
  const std::string& prefix() const { return prefix_; }

 private:
  std::string named(std::string_view name) const { return std::string(prefix_).append(name); }  // as SectionSaver's
  std::shared_ptr<const SectionFile> file_;
  std::string prefix_;
};

// What every saved accelerator keeps besides its own state, `PREFIX` + "common" (24 bytes):
//   offset  size  field
//        0     8  triangles the structure answers for, uint64
//        8     8  build seconds, double (as measured when it was built)
//       16     8  build peak bytes, uint64 (BuildReport::peak_bytes)
struct SavedCommonState {
  std::uint64_t triangles;
  double build_seconds;
  std::uint64_t build_peak_bytes;
};
static_assert(sizeof(SavedCommonState) == 24);

template <typename Archive, typename Report>
void archive_common_state(Archive& a, auto& triangles, Report& build) {
  SavedCommonState common{triangles, build.seconds, build.peak_bytes};
  a.value("common", common);
  if constexpr (Archive::kLoading) {
    triangles = static_cast<std::remove_reference_t<decltype(triangles)>>(common.triangles);
    build.seconds = common.build_seconds;
    build.peak_bytes = static_cast<std::size_t>(common.build_peak_bytes);
  }
}

}  // namespace wavetrace
