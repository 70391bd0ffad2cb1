// Scene file reading (toml++): each object is loaded, transformed and appended in file order.
#include "wavetrace/scene/scene_file.hpp"

#include <cmath>
#include <filesystem>
#include <set>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <toml++/toml.h>

#include "wavetrace/memory/process_memory.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/mesh_io.hpp"
#include "wavetrace/scene/object_transform.hpp"
#include "wavetrace/scene/scene_assembly.hpp"
#include "wavetrace/scene/shapes.hpp"
#include "wavetrace/scene/subdivide.hpp"

namespace wavetrace {
namespace {

// One table of the file, read with every key checked: `what` names it in every error.
class TableReader {
 public:
  TableReader(const toml::table& table, std::string what, std::set<std::string> known)
      : table_(table), what_(std::move(what)) {
    for (const auto& [key, node] : table) {
      if (known.count(std::string(key.str())) == 0) {
        std::string list;
        for (const std::string& name : known) list += (list.empty() ? "" : ", ") + name;
        throw SceneError(fmt::format("{}: unknown key '{}' (known: {})", what_, key.str(), list));
      }
    }
  }

  const std::string& what() const { return what_; }
  bool has(std::string_view key) const { return table_.contains(key); }

  std::string text(std::string_view key) const {
    const auto value = table_[key].value_exact<std::string>();
    if (!value) throw SceneError(fmt::format("{}: {} must be a string", what_, key));
    return *value;
  }
  double number(std::string_view key) const {
    const toml::node* node = table_.get(key);
    if (node == nullptr || !node->is_number() || !std::isfinite(*node->value<double>())) {
      throw SceneError(fmt::format("{}: {} must be a finite number", what_, key));
    }
    return *node->value<double>();
  }
  std::int64_t integer(std::string_view key, std::int64_t low, std::int64_t high) const {
    const auto value = table_[key].value_exact<std::int64_t>();
    if (!value || *value < low || *value > high) {
      throw SceneError(fmt::format("{}: {} must be an integer in [{}, {}]", what_, key, low, high));
    }
    return *value;
  }
  // [x, y, z] of finite numbers, or (where `splat` allows) one number for all three.
  glm::vec3 vector(std::string_view key, bool splat) const {
    const toml::node* node = table_.get(key);
    if (splat && node != nullptr && node->is_number()) return glm::vec3(static_cast<float>(number(key)));
    const toml::array* array = node == nullptr ? nullptr : node->as_array();
    glm::vec3 result;
    bool valid = array != nullptr && array->size() == 3;
    for (std::size_t axis = 0; valid && axis < 3; ++axis) {
      const toml::node& component = *array->get(axis);
      valid = component.is_number() && std::isfinite(*component.value<double>());
      if (valid) result[static_cast<int>(axis)] = static_cast<float>(*component.value<double>());
    }
    if (!valid) {
      throw SceneError(fmt::format("{}: {} must be [x, y, z] of finite numbers{}", what_, key,
                                   splat ? " or one number" : ""));
    }
    return result;
  }
  const toml::table* table(std::string_view key) const {
    const toml::table* value = table_[key].as_table();
    if (value == nullptr) throw SceneError(fmt::format("{}: {} must be a table ({} = {{ ... }})", what_, key, key));
    return value;
  }
  glm::vec3 color(std::string_view key, float high) const {
    const glm::vec3 value = vector(key, true);
    for (int channel = 0; channel < 3; ++channel) {
      if (value[channel] < 0.0f || value[channel] > high) {
        throw SceneError(fmt::format("{}: {} components must be in [0, {:g}]", what_, key, high));
      }
    }
    return value;
  }

 private:
  const toml::table& table_;
  std::string what_;
};

// The tables of an array of tables such as [[object]].
std::vector<const toml::table*> tables_of(const toml::table& root, std::string_view key, const std::string& file) {
  std::vector<const toml::table*> tables;
  const toml::node* node = root.get(key);
  if (node == nullptr) return tables;
  const toml::array* array = node->as_array();
  if (array == nullptr) throw SceneError(fmt::format("{}: '{}' must be written [[{}]] tables", file, key, key));
  for (const toml::node& item : *array) {
    if (item.as_table() == nullptr) throw SceneError(fmt::format("{}: '{}' must be written [[{}]] tables", file, key, key));
    tables.push_back(item.as_table());
  }
  return tables;
}

constexpr float kMaxAlbedo = 1.0f;
constexpr float kMaxEmission = 1e6f;
// Indices of refraction from air's to past diamond's (2.42) and the densest glasses'.
constexpr double kMinIor = 1.0, kMaxIor = 4.0;

// The object's mesh and its own materials (a builtin's, or the default for a file).
struct ObjectGeometry {
  TriangleMesh mesh;
  std::vector<Material> materials;
};

ObjectGeometry load_object_geometry(const std::string& source, const std::filesystem::path& directory,
                                    const std::string& what) {
  try {
    if (is_builtin_scene(source)) {
      Scene builtin = make_builtin_scene(source);
      return {std::move(builtin.mesh), std::move(builtin.materials)};
    }
    if (is_scene_file(source)) throw SceneError("a scene file cannot hold another scene file");
    const std::filesystem::path path =
        std::filesystem::path(source).is_absolute() ? std::filesystem::path(source) : directory / source;
    return {load_mesh_file(path.string()).mesh, {Material{}}};
  } catch (const SceneError& error) {
    throw SceneError(fmt::format("{}: {}", what, error.what()));
  }
}

// The triangles the objects may still make: each is charged before it is built.
class TriangleBudget {
 public:
  explicit TriangleBudget(const SceneFileLimits& limits) {
    const std::size_t available = available_memory_bytes();
    left_ = limits.max_triangles > 0 ? double(limits.max_triangles)
            : available > 0         ? double(available) / kSubdividedBytesPerTriangle
                                    : 1e300;
    total_ = left_;
  }
  // `triangles` of `what` (before `levels` of subdivision) fit, or SceneError.
  void charge(std::size_t triangles, int levels, const std::string& what) {
    const double made = double(triangles) * std::pow(4.0, levels);
    if (made > left_) {
      throw SceneError(fmt::format("{}: makes {:.4g} triangles{}, past what the scene may hold ({:.4g} in all, "
                                   "{:.4g} left{})",
                                   what, made, levels > 0 ? fmt::format(" subdivided {} times", levels) : "", total_,
                                   left_, total_ >= 1e300 ? "" : " for the memory available"));
    }
    left_ -= made;
  }

 private:
  double left_, total_;
};

// An object's material: `material = { type, albedo, emission, ior }`, or the shorthand of
// `albedo` and `emission` beside the mesh (diffuse), never both.
Material object_material(const TableReader& object) {
  if (!object.has("material")) {
    Material material;
    if (object.has("albedo")) material.albedo = object.color("albedo", kMaxAlbedo);
    if (object.has("emission")) material.emission = object.color("emission", kMaxEmission);
    return material;
  }
  if (object.has("albedo") || object.has("emission")) {
    throw SceneError(fmt::format("{}: give albedo and emission inside 'material', not beside it", object.what()));
  }
  const toml::table* table = object.table("material");
  const TableReader reader(*table, object.what() + ": material", {"type", "albedo", "emission", "ior"});
  Material material;
  if (reader.has("type")) {
    try {
      material.surface = parse_surface(reader.text("type"));
    } catch (const SceneError& error) {
      throw SceneError(fmt::format("{}: {}", reader.what(), error.what()));
    }
  }
  // A mirror or glass reflects (and glass transmits) all light unless tinted.
  if (material.specular()) material.albedo = glm::vec3(1.0f);
  if (reader.has("albedo")) material.albedo = reader.color("albedo", kMaxAlbedo);
  if (reader.has("emission")) material.emission = reader.color("emission", kMaxEmission);
  if (reader.has("ior")) {
    if (material.surface != Surface::glass) throw SceneError(fmt::format("{}: ior is for glass only", reader.what()));
    const double ior = reader.number("ior");
    if (ior < kMinIor || ior > kMaxIor) {
      throw SceneError(fmt::format("{}: ior must be in [{:g}, {:g}]", reader.what(), kMinIor, kMaxIor));
    }
    material.ior = static_cast<float>(ior);
  }
  return material;
}

void add_object(SceneAssembly& assembly, const TableReader& object, const std::filesystem::path& directory,
                TriangleBudget& budget) {
  if (!object.has("mesh")) throw SceneError(fmt::format("{}: 'mesh' is required", object.what()));
  ObjectTransform transform;
  if (object.has("fit")) transform.fit = static_cast<float>(object.number("fit"));
  if (object.has("scale")) transform.scale = object.vector("scale", true);
  if (object.has("rotate")) transform.rotate_degrees = object.vector("rotate", false);
  if (object.has("translate")) transform.translate = object.vector("translate", false);
  validate_transform(transform, object.what());
  const int subdivide = object.has("subdivide") ? static_cast<int>(object.integer("subdivide", 0, 6)) : 0;
  const bool own_material = object.has("albedo") || object.has("emission") || object.has("material");
  const Material material = object_material(object);

  const std::string source = object.text("mesh");
  // A builtin is charged before it is generated, a mesh file once read (its size bounds it).
  std::optional<std::size_t> builtin_triangles;
  try {
    if (is_builtin_scene(source)) builtin_triangles = builtin_triangle_count(source);
  } catch (const SceneError& error) {
    throw SceneError(fmt::format("{}: {}", object.what(), error.what()));
  }
  if (builtin_triangles) budget.charge(*builtin_triangles, subdivide, object.what());
  ObjectGeometry geometry = load_object_geometry(source, directory, object.what());
  if (!builtin_triangles) budget.charge(geometry.mesh.triangle_count(), subdivide, object.what());
  if (subdivide > 0) geometry.mesh = loop_subdivide(geometry.mesh, subdivide).mesh;
  apply_transform(geometry.mesh, transform, object.what());
  if (own_material) {
    assembly.add(geometry.mesh, assembly.add_material(material));
  } else {
    assembly.add(geometry.mesh, geometry.materials);
  }
}

void add_light(SceneAssembly& assembly, const TableReader& light) {
  for (const char* key : {"corner", "edge_u", "edge_v", "emission"}) {
    if (!light.has(key)) throw SceneError(fmt::format("{}: '{}' is required", light.what(), key));
  }
  const glm::vec3 edge_u = light.vector("edge_u", false), edge_v = light.vector("edge_v", false);
  const glm::dvec3 normal = glm::cross(glm::dvec3(edge_u), glm::dvec3(edge_v));
  if (normal == glm::dvec3(0.0)) {
    throw SceneError(fmt::format("{}: edge_u and edge_v span no area", light.what()));
  }
  Material material{glm::vec3(0.0f), light.color("emission", kMaxEmission)};
  if (!material.emissive()) throw SceneError(fmt::format("{}: emission must be positive", light.what()));
  assembly.add(make_quad(light.vector("corner", false), edge_u, edge_v), assembly.add_material(material));
}

std::string object_label(const char* kind, std::size_t index, const toml::table& table, const std::string& file) {
  const auto name = table["name"].value_exact<std::string>();
  return name ? fmt::format("{}: {} '{}' (#{})", file, kind, *name, index + 1)
              : fmt::format("{}: {} #{}", file, kind, index + 1);
}

}  // namespace

bool is_scene_file(std::string_view source) { return source.ends_with(".toml"); }

Scene load_scene_file(const std::string& path, const SceneFileLimits& limits) {
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& error) {
    if (!std::filesystem::exists(path)) throw SceneError(fmt::format("{}: no such scene file", path));
    throw SceneError(fmt::format("{}:{}:{}: {}", path, error.source().begin.line, error.source().begin.column,
                                 error.description()));
  }
  const TableReader top(root, path, {"background", "camera", "object", "light"});
  const std::filesystem::path directory = std::filesystem::path(path).parent_path();

  SceneAssembly assembly;
  TriangleBudget budget(limits);
  const auto objects = tables_of(root, "object", path);
  const auto lights = tables_of(root, "light", path);
  if (objects.empty() && lights.empty()) throw SceneError(fmt::format("{}: the scene has no [[object]]", path));
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const TableReader object(*objects[i], object_label("object", i, *objects[i], path),
                             {"name", "mesh", "fit", "scale", "rotate", "translate", "subdivide", "albedo", "emission",
                              "material"});
    add_object(assembly, object, directory, budget);
  }
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const TableReader light(*lights[i], object_label("light", i, *lights[i], path),
                            {"name", "corner", "edge_u", "edge_v", "emission"});
    add_light(assembly, light);
  }

  const glm::vec3 background = top.has("background") ? top.color("background", kMaxEmission) : glm::vec3(0.0f);
  Scene scene = std::move(assembly).finish(path, background);
  if (top.has("camera")) {
    const toml::table* table = root["camera"].as_table();
    if (table == nullptr) throw SceneError(fmt::format("{}: camera must be a [camera] table", path));
    const TableReader camera(*table, path + ": camera", {"position", "look_at", "up", "fov"});
    if (!camera.has("position") || !camera.has("look_at")) {
      throw SceneError(fmt::format("{}: position and look_at are required", camera.what()));
    }
    Camera view;
    view.position = camera.vector("position", false);
    view.look_at = camera.vector("look_at", false);
    if (camera.has("up")) view.up = camera.vector("up", false);
    if (camera.has("fov")) view.vertical_fov_degrees = static_cast<float>(camera.number("fov"));
    try {
      validate_camera(view);
    } catch (const SceneError& error) {
      throw SceneError(fmt::format("{}: {}", camera.what(), error.what()));
    }
    scene.camera = view;
  }
  return scene;
}

}  // namespace wavetrace
