// The byte layout of a section file, the container of saved worlds (.wtw): a header, named
// sections of raw data each at a 4 KiB-aligned offset (so any array in it can be used in
// place from a mapping, and read with O_DIRECT), and a table of sections at the end. All
// integers little-endian; checksums are XXH3-64 (seed 0) from Debian's libxxhash.
//
// Header, at offset 0 (64 bytes):
//   offset  size  field
//        0     8  magic "WAVEWRLD"
//        8     4  container version (kSectionFileVersion)
//       12     4  section count n
//       16     8  table offset in bytes (a multiple of 8)
//       24     8  file size in bytes (a multiple of 4096: the last section is zero padded)
//       32     8  XXH3-64 of the table's n * 96 bytes
//       40     8  XXH3-64 of header bytes 0-39
//       48    16  zero
//
// Table entry i (96 bytes, at table offset + 96 i), sorted by name:
//        0    64  name: UTF-8, NUL-padded, at most 63 bytes ("chunk.17/hmq.blocks")
//       64     8  data offset in bytes (a multiple of 4096; header and table never overlap data)
//       72     8  data size in bytes (the padding after it is not part of it)
//       80     8  XXH3-64 of the data
//       88     4  element size in bytes: the size of the array's type, so that a reader can
//                 refuse a section whose size is no whole number of elements
//       92     4  zero
//
// The meaning of each section (and the version of each accelerator's own format) is
// written beside the code that saves it: accel/saved_world_format.hpp and the formats of
// each accelerator.
#pragma once

#include <cstddef>
#include <cstdint>

namespace wavetrace::section_file {

inline constexpr char kMagic[8] = {'W', 'A', 'V', 'E', 'W', 'R', 'L', 'D'};
inline constexpr std::uint32_t kSectionFileVersion = 1;
inline constexpr std::size_t kDataAlignment = 4096;
inline constexpr std::size_t kNameBytes = 64;

struct Header {
  char magic[8];
  std::uint32_t version;
  std::uint32_t section_count;
  std::uint64_t table_offset;
  std::uint64_t file_size;
  std::uint64_t table_checksum;
  std::uint64_t header_checksum;
  std::uint8_t zero[16];
};
static_assert(sizeof(Header) == 64);
inline constexpr std::size_t kHeaderChecksummedBytes = 40;

struct TableEntry {
  char name[kNameBytes];
  std::uint64_t offset;
  std::uint64_t size;
  std::uint64_t checksum;
  std::uint32_t element_bytes;
  std::uint32_t zero;
};
static_assert(sizeof(TableEntry) == 96);

}  // namespace wavetrace::section_file
