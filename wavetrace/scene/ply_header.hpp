// The header of a PLY file, ASCII or binary: its elements and their properties, parsed and
// checked once for both readers (ply_file.hpp streams binary bodies, ply_text_reader.cpp
// reads ASCII ones).
//
//   ply
//   format ascii 1.0                          (or binary_little_endian / binary_big_endian)
//   comment ...                               (any, also obj_info)
//   element vertex N
//   property float x                          (any scalar type; x, y, z in any position,
//   property float y                           other properties are skipped)
//   property float z
//   element face M
//   property list uchar int vertex_indices    (count and index of integer types, also named
//                                              vertex_index; other face properties skipped)
//   end_header
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace wavetrace {

enum class PlyType { int8, uint8, int16, uint16, int32, uint32, float32, float64 };
enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::float32;  // of the items, for a list
  bool list = false;
  PlyType count_type = PlyType::uint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  bool fixed_size() const;
  std::size_t record_bytes() const;  // binary bytes of one record (fixed-size elements)
};

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t vertex_element = 0, face_element = 0;
  std::size_t body_offset = 0;  // bytes from the file's start to the first record
  std::size_t lines = 0;        // lines of the header, end_header's included
};

// A header longer than this is refused (one of comments only would otherwise be read whole).
inline constexpr std::size_t kMaxPlyHeaderBytes = std::size_t{1} << 20;

std::size_t ply_type_bytes(PlyType type);
bool ply_type_is_integer(PlyType type);

// Parses the header at the start of `text`, checking that vertices have x, y and z and faces
// one integer list of vertex indices. Throws SceneError "PATH: PLY header line N: PROBLEM".
PlyHeader parse_ply_header(std::string_view text, const std::string& path);
// The same, reading at most kMaxPlyHeaderBytes of the file.
PlyHeader read_ply_header(const std::string& path);

}  // namespace wavetrace
