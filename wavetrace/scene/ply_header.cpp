// The PLY header parser shared by the binary and ASCII readers.
#include "wavetrace/scene/ply_header.hpp"

#include <algorithm>
#include <fstream>
#include <unordered_map>

#include <fmt/format.h>

#include "wavetrace/scene/text_lines.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {
namespace {

bool parse_type(std::string_view name, PlyType& type) {
  static const std::unordered_map<std::string_view, PlyType> types = {
      {"char", PlyType::int8},     {"int8", PlyType::int8},       {"uchar", PlyType::uint8},    {"uint8", PlyType::uint8},
      {"short", PlyType::int16},   {"int16", PlyType::int16},     {"ushort", PlyType::uint16},  {"uint16", PlyType::uint16},
      {"int", PlyType::int32},     {"int32", PlyType::int32},     {"uint", PlyType::uint32},    {"uint32", PlyType::uint32},
      {"float", PlyType::float32}, {"float32", PlyType::float32}, {"double", PlyType::float64}, {"float64", PlyType::float64}};
  const auto found = types.find(name);
  if (found == types.end()) return false;
  type = found->second;
  return true;
}

bool is_vertex_list(const PlyProperty& property) {
  return property.list && (property.name == "vertex_indices" || property.name == "vertex_index");
}

}  // namespace

std::size_t ply_type_bytes(PlyType type) {
  switch (type) {
    case PlyType::int8: case PlyType::uint8: return 1;
    case PlyType::int16: case PlyType::uint16: return 2;
    case PlyType::int32: case PlyType::uint32: case PlyType::float32: return 4;
    case PlyType::float64: return 8;
  }
  return 0;
}

bool ply_type_is_integer(PlyType type) { return type != PlyType::float32 && type != PlyType::float64; }

bool PlyElement::fixed_size() const {
  return std::none_of(properties.begin(), properties.end(), [](const PlyProperty& p) { return p.list; });
}

std::size_t PlyElement::record_bytes() const {
  std::size_t bytes = 0;
  for (const PlyProperty& property : properties) bytes += ply_type_bytes(property.type);
  return bytes;
}

PlyHeader parse_ply_header(std::string_view text, const std::string& path) {
  PlyHeader header;
  bool format_seen = false;
  std::size_t number = 0;
  const auto fail = [&](const std::string& problem) {
    throw SceneError(fmt::format("{}: PLY header line {}: {}", path, number, problem));
  };
  // One TextLines per line, numbered as ours, for its splitting and number parsing.
  std::vector<std::string_view> words;
  std::size_t at = 0;
  while (true) {
    if (at >= text.size()) {
      ++number;
      fail(text.size() >= kMaxPlyHeaderBytes ? fmt::format("no end_header in the first {} bytes", kMaxPlyHeaderBytes)
                                             : std::string("the header has no end_header"));
    }
    const std::size_t end = text.find('\n', at);
    const std::string_view line = text.substr(at, end == std::string_view::npos ? text.size() - at : end - at);
    at = end == std::string_view::npos ? text.size() : end + 1;
    ++number;
    TextLines fields(line, path + ": PLY header", '\0', number);
    if (!fields.next(words)) words.clear();
    const std::string_view keyword = words.empty() ? std::string_view() : words[0];
    if (number == 1) {
      if (keyword != "ply" || words.size() != 1) fail("not a PLY file (it must start with 'ply')");
      continue;
    }
    if (keyword == "end_header") break;
    if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) continue;
    if (keyword == "format") {
      if (words.size() != 3) fail("the format line needs a format and a version");
      if (words[1] == "ascii") header.format = PlyFormat::ascii;
      else if (words[1] == "binary_little_endian") header.format = PlyFormat::binary_little_endian;
      else if (words[1] == "binary_big_endian") header.format = PlyFormat::binary_big_endian;
      else fail(fmt::format("unknown format '{}'", words[1].substr(0, 40)));
      if (words[2] != "1.0") fail("only PLY version 1.0 exists");
      format_seen = true;
    } else if (keyword == "element") {
      if (words.size() != 3) fail("an element needs a name and a count");
      PlyElement element;
      element.name = words[1];
      element.count = static_cast<std::uint64_t>(
          fields.integer(words[2], "the element count", 0, std::int64_t{1} << 48));
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) fail("a property before any element");
      PlyProperty property;
      if (words.size() == 5 && words[1] == "list") {
        property.list = true;
        property.name = words[4];
        if (!parse_type(words[2], property.count_type) || !parse_type(words[3], property.type)) {
          fail(fmt::format("unknown list types '{} {}'", words[2].substr(0, 20), words[3].substr(0, 20)));
        }
        if (!ply_type_is_integer(property.count_type)) fail("a list's count must be of an integer type");
      } else if (words.size() == 3) {
        property.name = words[2];
        if (!parse_type(words[1], property.type)) fail(fmt::format("unknown property type '{}'", words[1].substr(0, 20)));
      } else {
        fail("a property needs a type and a name (or 'list', two types and a name)");
      }
      header.elements.back().properties.push_back(property);
    } else {
      fail(fmt::format("unknown keyword '{}'", keyword.substr(0, 40)));
    }
  }
  header.body_offset = at;
  header.lines = number;
  if (!format_seen) throw SceneError(fmt::format("{}: PLY header without a format line", path));
  const auto find = [&](const char* name) {
    const auto found = std::find_if(header.elements.begin(), header.elements.end(),
                                    [&](const PlyElement& element) { return element.name == name; });
    if (found == header.elements.end()) throw SceneError(fmt::format("{}: PLY file without a '{}' element", path, name));
    if (std::find_if(found + 1, header.elements.end(), [&](const PlyElement& e) { return e.name == name; }) !=
        header.elements.end()) {
      throw SceneError(fmt::format("{}: PLY file with two '{}' elements", path, name));
    }
    return static_cast<std::size_t>(found - header.elements.begin());
  };
  header.vertex_element = find("vertex");
  header.face_element = find("face");
  const PlyElement& vertex = header.elements[header.vertex_element];
  for (const char* axis : {"x", "y", "z"}) {
    const auto named = std::count_if(vertex.properties.begin(), vertex.properties.end(),
                                     [&](const PlyProperty& p) { return p.name == axis; });
    if (named != 1) throw SceneError(fmt::format("{}: PLY vertices need one '{}' property", path, axis));
  }
  for (const PlyProperty& property : vertex.properties) {
    if (property.list) throw SceneError(fmt::format("{}: PLY vertex list '{}' is not supported", path, property.name));
  }
  const PlyElement& face = header.elements[header.face_element];
  if (std::count_if(face.properties.begin(), face.properties.end(), is_vertex_list) != 1) {
    throw SceneError(fmt::format("{}: PLY faces need one 'vertex_indices' list", path));
  }
  for (const PlyProperty& property : face.properties) {
    if (property.list && !is_vertex_list(property)) {
      throw SceneError(fmt::format("{}: PLY face list '{}' is not supported", path, property.name));
    }
    if (is_vertex_list(property) && !ply_type_is_integer(property.type)) {
      throw SceneError(fmt::format("{}: PLY vertex indices must be integers", path));
    }
  }
  return header;
}

PlyHeader read_ply_header(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw SceneError(fmt::format("{}: no such mesh file", path));
  // Read in growing pieces until the end_header line has been read whole, up to the limit.
  std::string start;
  const auto complete = [&] {
    const std::size_t end_line = start.find("\nend_header");
    return end_line != std::string::npos && start.find('\n', end_line + 1) != std::string::npos;
  };
  std::size_t piece = 4096;
  while (start.size() < kMaxPlyHeaderBytes && !complete() && file) {
    const std::size_t had = start.size();
    start.resize(std::min(had + piece, kMaxPlyHeaderBytes));
    file.read(start.data() + had, static_cast<std::streamsize>(start.size() - had));
    start.resize(had + static_cast<std::size_t>(file.gcount()));
    piece *= 2;
  }
  return parse_ply_header(start, path);
}

}  // namespace wavetrace
