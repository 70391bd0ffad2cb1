// The binary PLY reader and writer of ply_file.hpp: a header parser, a buffered record
// reader that swaps bytes for big-endian files, and faces fanned into triangles.
#include "wavetrace/scene/ply_file.hpp"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <unordered_map>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "wavetrace/scene/ply_header.hpp"

namespace wavetrace {

struct PlyTriangleSource::Layout {
  PlyHeader header;
  bool little_endian = true;
  std::uint64_t vertex_offset = 0, face_offset = 0;  // file offsets of the first records
};

namespace {

// Faces are read in chunks of this many bytes.
constexpr std::size_t kReadBuffer = std::size_t{1} << 20;

// Sequential reads of one file through a buffer, with the file's byte order.
class RecordReader {
 public:
  RecordReader(const std::string& path, std::uint64_t offset, bool little_endian)
      : path_(path), file_(std::fopen(path.c_str(), "rb")), swap_(little_endian != (std::endian::native == std::endian::little)) {
    if (file_ == nullptr) throw SceneError(fmt::format("{}: cannot open the file", path));
    if (std::fseek(file_, static_cast<long>(offset), SEEK_SET) != 0) throw SceneError(fmt::format("{}: cannot seek", path));
    std::error_code status;
    const std::uintmax_t size = std::filesystem::file_size(path, status);
    buffer_.resize(status || size <= offset ? 1 : std::min<std::uintmax_t>(kReadBuffer, size - offset));
  }
  ~RecordReader() { std::fclose(file_); }
  RecordReader(const RecordReader&) = delete;
  RecordReader& operator=(const RecordReader&) = delete;

  std::uint64_t position() const { return consumed_; }

  void read_bytes(void* out, std::size_t bytes) {
    auto* to = static_cast<std::byte*>(out);
    while (bytes > 0) {
      if (next_ == filled_) refill();
      const std::size_t take = std::min(bytes, filled_ - next_);
      std::memcpy(to, buffer_.data() + next_, take);
      next_ += take;
      to += take;
      bytes -= take;
      consumed_ += take;
    }
  }
  void skip(std::size_t bytes) {
    std::byte sink[64];
    while (bytes > 0) {
      const std::size_t take = std::min(bytes, sizeof sink);
      read_bytes(sink, take);
      bytes -= take;
    }
  }
  // One scalar of `type`, as a double (exact for every PLY type).
  double read_scalar(PlyType type) {
    std::byte raw[8];
    const std::size_t bytes = ply_type_bytes(type);
    read_bytes(raw, bytes);
    if (swap_) std::reverse(raw, raw + bytes);
    switch (type) {
      case PlyType::int8: return double(std::bit_cast<std::int8_t>(raw[0]));
      case PlyType::uint8: return double(std::to_integer<std::uint8_t>(raw[0]));
      case PlyType::int16: return double(load<std::int16_t>(raw));
      case PlyType::uint16: return double(load<std::uint16_t>(raw));
      case PlyType::int32: return double(load<std::int32_t>(raw));
      case PlyType::uint32: return double(load<std::uint32_t>(raw));
      case PlyType::float32: return double(load<float>(raw));
      case PlyType::float64: return load<double>(raw);
    }
    return 0.0;
  }

 private:
  template <typename T>
  static T load(const std::byte* raw) {
    T value;
    std::memcpy(&value, raw, sizeof value);
    return value;
  }
  void refill() {
    filled_ = std::fread(buffer_.data(), 1, buffer_.size(), file_);
    next_ = 0;
    if (filled_ == 0) throw SceneError(fmt::format("{}: truncated (the file ends inside its data)", path_));
  }
  std::string path_;
  std::FILE* file_;
  bool swap_;
  std::vector<std::byte> buffer_;
  std::size_t next_ = 0, filled_ = 0;
  std::uint64_t consumed_ = 0;
};

std::shared_ptr<PlyTriangleSource::Layout> read_layout(const std::string& path) {
  auto layout = std::make_shared<PlyTriangleSource::Layout>();
  layout->header = read_ply_header(path);
  const PlyHeader& header = layout->header;
  if (header.format == PlyFormat::ascii) throw SceneError(fmt::format("{}: an ASCII PLY file, not binary", path));
  layout->little_endian = header.format == PlyFormat::binary_little_endian;
  if (header.face_element < header.vertex_element) {
    throw SceneError(fmt::format("{}: binary PLY faces before vertices are not supported", path));
  }
  std::uint64_t offset = header.body_offset;
  for (std::size_t e = 0; e < header.face_element; ++e) {
    const PlyElement& element = header.elements[e];
    if (!element.fixed_size()) {
      throw SceneError(fmt::format("{}: PLY element '{}' before the faces has list properties", path, element.name));
    }
    if (e == header.vertex_element) layout->vertex_offset = offset;
    offset += element.count * element.record_bytes();
  }
  layout->face_offset = offset;
  return layout;
}

bool degenerate(const std::vector<glm::vec3>& positions, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  if (a == b || b == c || a == c) return true;
  const glm::dvec3 pa(positions[a]), pb(positions[b]), pc(positions[c]);
  const glm::dvec3 normal = glm::cross(pb - pa, pc - pa);
  return normal.x == 0.0 && normal.y == 0.0 && normal.z == 0.0;
}

// Reads faces one at a time and hands each kept triangle, fanned, to `emit`.
class FaceReader {
 public:
  FaceReader(const std::string& path, const PlyTriangleSource::Layout& layout, const std::vector<glm::vec3>& positions)
      : path_(path),
        face_(layout.header.elements[layout.header.face_element]),
        reader_(path, layout.face_offset, layout.little_endian),
        positions_(positions) {}

  std::size_t faces_read() const { return faces_read_; }

  // The next face's triangles; false when every face was read.
  template <typename Emit>
  bool next(Emit&& emit, std::size_t& polygons, std::size_t& dropped) {
    if (faces_read_ == face_.count) return false;
    corners_.clear();
    for (const PlyProperty& property : face_.properties) {
      if (!property.list) {
        reader_.skip(ply_type_bytes(property.type));
        continue;
      }
      const double count = reader_.read_scalar(property.count_type);
      if (count < 3) {
        throw SceneError(fmt::format("{}: face {} has {} corners (at least 3 needed)", path_, faces_read_, count));
      }
      for (double k = 0; k < count; ++k) {
        const double index = reader_.read_scalar(property.type);
        if (!(index >= 0.0 && index < double(positions_.size()))) {
          throw SceneError(fmt::format("{}: face {} references vertex {} but there are only {} vertices", path_,
                                       faces_read_, index, positions_.size()));
        }
        corners_.push_back(static_cast<std::uint32_t>(index));
      }
    }
    if (corners_.size() > 3) ++polygons;
    for (std::size_t k = 1; k + 1 < corners_.size(); ++k) {
      if (degenerate(positions_, corners_[0], corners_[k], corners_[k + 1])) {
        ++dropped;
        continue;
      }
      emit(glm::uvec3(corners_[0], corners_[k], corners_[k + 1]));
    }
    ++faces_read_;
    return true;
  }

 private:
  std::string path_;
  const PlyElement& face_;
  RecordReader reader_;
  const std::vector<glm::vec3>& positions_;
  std::vector<std::uint32_t> corners_;
  std::size_t faces_read_ = 0;
};

}  // namespace

bool is_binary_ply(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::string first, second;
  if (!std::getline(file, first) || !std::getline(file, second)) return false;
  while (second.starts_with("comment") && std::getline(file, second)) {}
  return (first == "ply" || first == "ply\r") && second.starts_with("format binary_");
}

PlyTriangleSource::PlyTriangleSource(const std::string& path) : path_(path), layout_(read_layout(path)) {
  const PlyElement& vertex = layout_->header.elements[layout_->header.vertex_element];
  if (vertex.count > std::numeric_limits<std::uint32_t>::max()) {
    throw SceneError(fmt::format("{}: {} vertices, beyond 32-bit indices", path, vertex.count));
  }
  const std::uint64_t needed = layout_->face_offset + layout_->header.elements[layout_->header.face_element].count;
  if (std::filesystem::file_size(path) < needed) {
    throw SceneError(fmt::format("{}: truncated ({} bytes, its header promises at least {})", path,
                                 std::filesystem::file_size(path), needed));
  }
  positions_.resize(vertex.count);
  RecordReader reader(path, layout_->vertex_offset, layout_->little_endian);
  for (std::size_t v = 0; v < vertex.count; ++v) {
    glm::dvec3 p(0.0);
    for (const PlyProperty& property : vertex.properties) {
      const double value = reader.read_scalar(property.type);
      if (property.name == "x") p.x = value;
      if (property.name == "y") p.y = value;
      if (property.name == "z") p.z = value;
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(p[axis]) || std::fabs(p[axis]) > kMaxCoordinateMagnitude) {
        throw SceneError(fmt::format("{}: vertex {} has a coordinate that is not finite or beyond {:g} ({}, {}, {})", path,
                                     v, kMaxCoordinateMagnitude, p.x, p.y, p.z));
      }
    }
    positions_[v] = glm::vec3(p);
    bounds_.extend(positions_[v]);
  }
  FaceReader faces(path, *layout_, positions_);
  while (faces.next([&](const glm::uvec3&) { ++triangles_; }, polygons_triangulated_, degenerate_dropped_)) {}
  if (triangles_ == 0) throw SceneError(fmt::format("{}: the mesh has no triangles", path));
}

// Triangles are numbered as the faces fan into them; a chunked build asks for ranges in
// order, so reading resumes where the last range ended. `pending` holds the triangles of
// the last face read that lay past that range.
struct PlyTriangleSource::Cursor {
  Cursor(const std::string& path, const Layout& layout, const std::vector<glm::vec3>& positions)
      : faces(path, layout, positions) {}
  FaceReader faces;
  std::size_t next_triangle = 0;  // the number of pending.front(), or of the next face's first
  std::vector<glm::uvec3> pending;
};

TriangleMesh PlyTriangleSource::extract(std::size_t first, std::size_t count) const {
  if (first > triangles_ || count > triangles_ - first) {
    throw std::out_of_range(fmt::format("{}: range [{}, {}) beyond its {} triangles", path_, first, first + count, triangles_));
  }
  const std::lock_guard lock(cursor_mutex_);
  if (!cursor_ || cursor_->next_triangle > first) cursor_ = std::make_shared<Cursor>(path_, *layout_, positions_);
  Cursor& cursor = *cursor_;
  TriangleMesh part;
  part.triangles.reserve(count);
  std::unordered_map<std::uint32_t, std::uint32_t> local_of;
  const auto take = [&](const glm::uvec3& corners) {
    const std::size_t number = cursor.next_triangle++;
    if (number < first) return;
    if (number >= first + count) {
      cursor.pending.push_back(corners);
      --cursor.next_triangle;  // not consumed
      return;
    }
    glm::uvec3 local;
    for (int k = 0; k < 3; ++k) {
      const auto [slot, added] = local_of.emplace(corners[k], static_cast<std::uint32_t>(part.positions.size()));
      if (added) part.positions.push_back(positions_[corners[k]]);
      local[k] = slot->second;
    }
    part.triangles.push_back(local);
  };
  std::vector<glm::uvec3> pending;
  pending.swap(cursor.pending);
  for (const glm::uvec3& corners : pending) take(corners);
  std::size_t polygons = 0, dropped = 0;
  while (part.triangles.size() < count && cursor.pending.empty() && cursor.faces.next(take, polygons, dropped)) {}
  part.positions.reserve(part.positions.size() + 1);  // read slack, as validate_and_clean leaves
  return part;
}

std::size_t write_binary_ply(const TriangleSource& source, const std::string& path, std::size_t piece_triangles) {
  const std::string faces_path = path + ".faces.partial";
  std::FILE* out = std::fopen(path.c_str(), "wb");
  std::FILE* faces = std::fopen(faces_path.c_str(), "wb+");
  if (out == nullptr || faces == nullptr) {
    if (out) std::fclose(out);
    if (faces) std::fclose(faces);
    throw SceneError(fmt::format("{}: cannot write", path));
  }
  // The vertex count is known only at the end: a fixed-width field rewritten in place.
  const auto header = [&](std::size_t vertices) {
    return fmt::format(
        "ply\nformat binary_little_endian 1.0\ncomment written by wavetrace export\nelement vertex {:020}\n"
        "property float x\nproperty float y\nproperty float z\nelement face {}\n"
        "property list uchar uint vertex_indices\nend_header\n",
        vertices, source.triangle_count());
  };
  bool ok = std::fputs(header(0).c_str(), out) >= 0;
  std::size_t vertices = 0;
  std::size_t first = 0;
  while (ok && first < source.triangle_count()) {
    const std::size_t count = std::min(piece_triangles, source.triangle_count() - first);
    const TriangleMesh piece = source.extract(first, count);
    ok &= std::fwrite(piece.positions.data(), sizeof(glm::vec3), piece.positions.size(), out) == piece.positions.size();
    std::vector<std::byte> records(piece.triangles.size() * 13);
    for (std::size_t t = 0; t < piece.triangles.size(); ++t) {
      records[13 * t] = std::byte{3};
      const glm::uvec3 global = piece.triangles[t] + static_cast<std::uint32_t>(vertices);
      std::memcpy(records.data() + 13 * t + 1, &global, 12);
    }
    ok &= std::fwrite(records.data(), 1, records.size(), faces) == records.size();
    vertices += piece.positions.size();
    if (vertices > std::numeric_limits<std::uint32_t>::max()) {
      ok = false;
      break;
    }
    first += count;
  }
  ok &= std::fseek(faces, 0, SEEK_SET) == 0;
  std::vector<char> copy(kReadBuffer);
  while (ok) {
    const std::size_t read = std::fread(copy.data(), 1, copy.size(), faces);
    if (read == 0) break;
    ok &= std::fwrite(copy.data(), 1, read, out) == read;
  }
  ok &= std::fseek(out, 0, SEEK_SET) == 0 && std::fputs(header(vertices).c_str(), out) >= 0;
  ok &= std::fclose(out) == 0;
  std::fclose(faces);
  std::filesystem::remove(faces_path);
  if (!ok) throw SceneError(fmt::format("{}: writing failed (disk full, or more than 2^32 vertices)", path));
  return vertices;
}

}  // namespace wavetrace
