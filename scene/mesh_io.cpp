// OpenMesh importer that keeps the file's faces exactly, feeding our indexed mesh.
#include "scene/mesh_io.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>

#include <fmt/format.h>
// MeshIO.hh registers the readers and must come before any mesh type.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>

namespace wavetrace {
namespace {

using OpenMesh::EdgeHandle;
using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::Vec2f;
using OpenMesh::Vec3d;
using OpenMesh::Vec3f;
using OpenMesh::Vec3uc;
using OpenMesh::Vec4f;
using OpenMesh::Vec4uc;
using OpenMesh::VertexHandle;
using OpenMesh::Attributes::StatusInfo;

// OpenMesh's TriMesh refuses faces that would make a vertex or edge non-manifold and only
// logs it; a ray tracer must render every triangle of the file, so we take the readers'
// callbacks directly. Attributes we do not use (normals, colours, texture coordinates,
// halfedge topology of the .om format) are accepted and ignored. One loss we cannot see:
// OpenMesh's OBJ reader itself drops faces with a repeated corner (degenerate anyway).
class TriangleListImporter final : public OpenMesh::IO::BaseImporter {
 public:
  explicit TriangleListImporter(LoadedMesh& out) : out_(out) {}

  std::optional<std::string> error;

  VertexHandle add_vertex(const Vec3f& point) override {
    out_.mesh.positions.emplace_back(point[0], point[1], point[2]);
    return VertexHandle(static_cast<int>(out_.mesh.positions.size() - 1));
  }
  VertexHandle add_vertex(const Vec3d& point) override { return add_vertex(Vec3f(point)); }
  VertexHandle add_vertex() override { return add_vertex(Vec3f(0.0f, 0.0f, 0.0f)); }

  FaceHandle add_face(const VHandles& corners) override {
    const std::size_t face = face_count_++;
    if (error) return FaceHandle();
    if (corners.size() < 3) {
      error = fmt::format("face {} has {} corners (at least 3 needed)", face, corners.size());
      return FaceHandle();
    }
    for (const VertexHandle& corner : corners) {
      if (!corner.is_valid() || static_cast<std::size_t>(corner.idx()) >= out_.mesh.positions.size()) {
        error = fmt::format("face {} references vertex {} but there are only {} vertices", face, corner.idx(),
                            out_.mesh.positions.size());
        return FaceHandle();
      }
    }
    if (corners.size() > 3) ++out_.polygons_triangulated;
    const auto index = [](const VertexHandle& handle) { return static_cast<std::uint32_t>(handle.idx()); };
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
      out_.mesh.triangles.emplace_back(index(corners[0]), index(corners[k]), index(corners[k + 1]));
    }
    return FaceHandle(static_cast<int>(face));
  }

  void set_point(VertexHandle vertex, const Vec3f& point) override {
    if (vertex.is_valid() && static_cast<std::size_t>(vertex.idx()) < out_.mesh.positions.size()) {
      out_.mesh.positions[vertex.idx()] = glm::vec3(point[0], point[1], point[2]);
    }
  }

  void reserve(unsigned int vertices, unsigned int edges, unsigned int faces) override {
    // Header counts are untrusted: cap what a lying header can make us allocate.
    constexpr unsigned int kMaxReserve = 1u << 26;
    out_.mesh.positions.reserve(std::min(vertices, kMaxReserve));
    out_.mesh.triangles.reserve(std::min(faces, kMaxReserve));
  }
  std::size_t n_vertices() const override { return out_.mesh.positions.size(); }
  std::size_t n_faces() const override { return face_count_; }
  std::size_t n_edges() const override { return 0; }

  // Accepted and ignored.
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_normal(VertexHandle, const Vec3f&) override {}
  void set_normal(VertexHandle, const Vec3d&) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_texcoord(VertexHandle, const Vec2f&) override {}
  void set_status(VertexHandle, const StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(HalfedgeHandle, const StatusInfo&) override {}
  void set_color(EdgeHandle, const Vec3uc&) override {}
  void set_color(EdgeHandle, const Vec4uc&) override {}
  void set_color(EdgeHandle, const Vec3f&) override {}
  void set_color(EdgeHandle, const Vec4f&) override {}
  void set_status(EdgeHandle, const StatusInfo&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void set_status(FaceHandle, const StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}

 private:
  LoadedMesh& out_;
  std::size_t face_count_ = 0;
};

}  // namespace

void silence_openmesh_logs() {
  static const bool silenced = [] {
    omlog().disable();
    omout().disable();
    omerr().disable();
    return true;
  }();
  (void)silenced;
}

LoadedMesh load_mesh_file(const std::string& path) {
  silence_openmesh_logs();
  std::error_code status;
  if (!std::filesystem::is_regular_file(path, status)) {
    throw SceneError(fmt::format("{}: no such mesh file", path));
  }
  // IOManager::can_read answers false for every format in OpenMesh 9.0, so check ourselves.
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  if (extension != ".off" && extension != ".ply" && extension != ".obj" && extension != ".stl") {
    throw SceneError(fmt::format("{}: unsupported mesh format (use .off, .ply, .obj or .stl)", path));
  }
  LoadedMesh loaded;
  TriangleListImporter importer(loaded);
  OpenMesh::IO::Options options;
  bool read_ok = false;
  try {
    read_ok = OpenMesh::IO::IOManager().read(path, importer, options);
  } catch (const std::exception& failure) {
    throw SceneError(fmt::format("{}: malformed mesh file ({})", path, failure.what()));
  }
  if (importer.error) throw SceneError(fmt::format("{}: {}", path, *importer.error));
  if (!read_ok) throw SceneError(fmt::format("{}: malformed mesh file (the reader rejected it)", path));
  loaded.cleanup = validate_and_clean(loaded.mesh, path);
  return loaded;
}

}  // namespace wavetrace
