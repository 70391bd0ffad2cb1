// The builtin scenes, composed from the procedural shapes.
#include "wavetrace/scene/builtin_scenes.hpp"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "wavetrace/scene/procedural_scene.hpp"
#include "wavetrace/scene/shapes.hpp"

namespace wavetrace {
namespace {

constexpr std::string_view kPrefix = "builtin:";
constexpr std::uint32_t kSeed = 1;
const glm::vec3 kWhiteSky(1.0f);

// A builtin scene as it is described: objects and materials, then assembled or streamed.
class ObjectList {
 public:
  std::uint32_t add_material(const Material& material) {
    materials_.push_back(material);
    return static_cast<std::uint32_t>(materials_.size() - 1);
  }
  void add(std::unique_ptr<ShapeGenerator> shape, std::uint32_t material, const glm::vec3& offset = glm::vec3(0.0f)) {
    objects_.push_back({std::move(shape), offset, {material}});
  }
  // A shape with materials of its own, which become scene materials in order.
  void add(std::unique_ptr<ShapeGenerator> shape, const std::vector<Material>& own) {
    ProceduralObject object{std::move(shape), glm::vec3(0.0f), {}};
    for (const Material& material : own) object.materials.push_back(add_material(material));
    objects_.push_back(std::move(object));
  }
  std::size_t triangle_count() const {
    std::size_t total = 0;
    for (const ProceduralObject& object : objects_) total += object.shape->triangle_count();
    return total;
  }

  Scene finish(std::string name, const glm::vec3& background, bool streamed) && {
    auto procedural = std::make_shared<ProceduralScene>(std::move(objects_));
    Scene scene;
    scene.name = std::move(name);
    scene.materials = std::move(materials_);
    scene.background = background;
    if (!streamed) {
      scene.mesh = procedural->assemble();
      scene.object_starts = procedural->object_starts();
      scene.cleanup = validate_and_clean(scene.mesh, scene.name, &scene.object_starts);
      scene.describe_mesh();
      return scene;
    }
    scene.triangle_count = procedural->triangle_count();
    for (const ProceduralObject& object : procedural->objects()) scene.vertex_count += object.shape->distinct_vertices();
    scene.bounds = procedural->bounds();
    validate_bounds(scene.bounds, scene.name);
    scene.material_runs = procedural->material_runs();
    scene.stream = std::move(procedural);
    return scene;
  }

 private:
  std::vector<ProceduralObject> objects_;
  std::vector<Material> materials_;
};

Scene single_object(std::string name, std::unique_ptr<ShapeGenerator> shape, const Material& material, bool streamed) {
  ObjectList objects;
  objects.add(std::move(shape), objects.add_material(material));
  return std::move(objects).finish(std::move(name), kWhiteSky, streamed);
}

// A closed room (the paper's Cornell box and Sponza play this part): walls, floor and
// ceiling facing inward, an area light under the ceiling, and detailed objects sharing the
// triangle budget. Every ray from inside hits something, so bounces are real work.
Scene make_room(std::string name, std::size_t triangles, bool streamed) {
  const glm::vec3 lower(-4.0f, 0.0f, -4.0f), upper(4.0f, 3.5f, 4.0f);
  const auto share = [&](double fraction) { return std::max<std::size_t>(20, std::size_t(double(triangles) * fraction)); };
  ObjectList objects;
  // Left wall red, right wall green, the rest white, as in a Cornell box.
  objects.add(room_shell_shape(lower, upper, share(0.04)),
              {Material{glm::vec3(0.63f, 0.065f, 0.05f)}, Material{glm::vec3(0.14f, 0.45f, 0.09f)},
               Material{glm::vec3(0.75f)}});
  // Just under the ceiling, facing down: the room stays closed without it.
  objects.add(quad_shape(glm::vec3(-0.8f, upper.y - 0.01f, -1.8f), glm::vec3(1.6f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, 1.6f)),
              objects.add_material(Material{glm::vec3(0.0f), glm::vec3(17.0f)}));
  objects.add(terrain_shape(share(0.20), 3.2f, 0.35f, kSeed), objects.add_material(Material{glm::vec3(0.55f, 0.5f, 0.4f)}),
              glm::vec3(-2.0f, 0.3f, -1.6f));
  objects.add(displaced_sphere_shape(share(0.28), glm::vec3(1.5f, 1.0f, -1.8f), 0.9f, kSeed),
              objects.add_material(Material{glm::vec3(0.80f, 0.45f, 0.25f)}));
  objects.add(displaced_sphere_shape(share(0.16), glm::vec3(-2.0f, 1.05f, -1.8f), 0.6f, kSeed + 1),
              objects.add_material(Material{glm::vec3(0.30f, 0.45f, 0.75f)}));
  objects.add(displaced_sphere_shape(share(0.10), glm::vec3(0.1f, 0.42f, 0.3f), 0.4f, kSeed + 2),
              objects.add_material(Material{glm::vec3(0.75f)}));
  const glm::vec3 fur_center(1.9f, 0.85f, 0.9f);
  const std::size_t fur = share(0.22);
  objects.add(displaced_sphere_shape(fur / 10, fur_center, 0.45f, kSeed + 3), objects.add_material(Material{glm::vec3(0.6f)}));
  objects.add(strands_shape(fur - fur / 10, 0.45f, 0.3f, 0.004f, kSeed),
              objects.add_material(Material{glm::vec3(0.85f, 0.65f, 0.4f)}), fur_center);
  Scene scene = std::move(objects).finish(std::move(name), glm::vec3(0.0f), streamed);
  scene.camera = Camera{glm::vec3(0.0f, 1.7f, 3.7f), glm::vec3(0.0f, 1.0f, -1.0f), glm::vec3(0.0f, 1.0f, 0.0f), 62.0f};
  scene.enclosure = Bounds3{lower, upper};
  return scene;
}

}  // namespace

bool is_builtin_scene(std::string_view source) { return source.starts_with(kPrefix); }

std::vector<std::string> builtin_scene_names() {
  return {"sphere", "ball", "plane", "terrain", "soup", "stadium", "fur", "default", "room", "furnace"};
}

std::size_t parse_triangle_count(std::string_view text, std::string_view what) {
  std::size_t multiplier = 1;
  std::string_view digits = text;
  if (!digits.empty()) {
    switch (digits.back()) {
      case 'k': case 'K': multiplier = 1000; break;
      case 'm': case 'M': multiplier = 1000000; break;
      case 'g': case 'G': multiplier = 1000000000; break;
      default: break;
    }
    if (multiplier != 1) digits.remove_suffix(1);
  }
  double value = 0.0;
  const auto [end, status] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || status != std::errc() || end != digits.data() + digits.size() || !(value >= 1.0) ||
      value * multiplier > 4.0e9) {
    throw SceneError(fmt::format("{}: triangle count '{}' is not a number in [1, 4G] (e.g. 250k, 8M)", what, text));
  }
  return static_cast<std::size_t>(value * multiplier);
}

std::optional<std::size_t> requested_triangle_count(std::string_view source) {
  const std::string_view spec = source.substr(kPrefix.size());
  const std::size_t colon = spec.find(':');
  if (colon == std::string_view::npos) return std::nullopt;
  return parse_triangle_count(spec.substr(colon + 1), source);
}

namespace {

// Each builtin's triangles when no count is given, and the fewest its structure can make.
struct BuiltinCount {
  std::string_view name;
  std::size_t fallback, least;
};
constexpr BuiltinCount kBuiltinCounts[] = {{"sphere", 1000000, 0},  {"ball", 20000, 0},       {"plane", 2, 0}, {"soup", 1000000, 0},
                                           {"terrain", 1000000, 0}, {"stadium", 1000000, 32}, {"fur", 1000000, 200},
                                           {"default", 200000, 0},  {"room", 1000000, 2000},  {"furnace", 20000, 0}};

std::string_view builtin_name(std::string_view source) {
  const std::string_view spec = source.substr(kPrefix.size());
  return spec.substr(0, spec.find(':'));
}

}  // namespace

std::optional<std::size_t> builtin_triangle_count(std::string_view source) {
  const std::string_view name = builtin_name(source);
  for (const BuiltinCount& count : kBuiltinCounts) {
    if (count.name == name) return std::max(requested_triangle_count(source).value_or(count.fallback), count.least);
  }
  return std::nullopt;
}

Scene make_builtin_scene(std::string_view source, bool streamed) {
  const std::string_view name = builtin_name(source);
  const std::string label(source);
  // The requested count or the builtin's default; each structure's floor is applied below.
  const BuiltinCount* const counted = std::find_if(std::begin(kBuiltinCounts), std::end(kBuiltinCounts),
                                                 [&](const BuiltinCount& count) { return count.name == name; });
  const std::size_t count =
      counted == std::end(kBuiltinCounts) ? 0 : requested_triangle_count(source).value_or(counted->fallback);
  if (name == "sphere") {
    return single_object(label, displaced_sphere_shape(count, glm::vec3(0.0f), 1.0f, kSeed),
                         Material{glm::vec3(0.7f)}, streamed);
  }
  if (name == "ball") return single_object(label, smooth_sphere_shape(count, glm::vec3(0.0f), 1.0f), Material{}, streamed);
  if (name == "plane") return single_object(label, terrain_shape(count, 2.0f, 0.0f, kSeed), Material{}, streamed);
  if (name == "furnace") {
    // Every wall emits kFurnaceEmission and reflects kFurnaceAlbedo diffusely, so the radiance
    // everywhere inside is emission / (1 - albedo): the closed form a renderer is checked by.
    Scene scene = single_object(label, smooth_sphere_shape(count, glm::vec3(0.0f), 1.0f, true),
                                Material{glm::vec3(kFurnaceAlbedo), glm::vec3(kFurnaceEmission)}, streamed);
    scene.camera = Camera{glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, -1.0f), glm::vec3(0.0f, 1.0f, 0.0f), 60.0f};
    return scene;
  }
  if (name == "soup") return single_object(label, soup_shape(count, kSeed), Material{glm::vec3(0.7f)}, streamed);
  if (name == "terrain") {
    return single_object(label, terrain_shape(count, 4.0f, 0.6f, kSeed), Material{glm::vec3(0.6f)}, streamed);
  }
  if (name == "stadium") {
    const std::size_t total = std::max<std::size_t>(count, 32);
    ObjectList objects;
    objects.add(displaced_sphere_shape(total - 12, glm::vec3(0.0f), 1.0f, kSeed), objects.add_material(Material{glm::vec3(0.7f)}));
    objects.add(inward_box_shape(glm::vec3(-500.0f), glm::vec3(500.0f)), objects.add_material(Material{glm::vec3(0.5f)}));
    Scene scene = std::move(objects).finish(label, kWhiteSky, streamed);
    scene.camera = Camera{glm::vec3(0.0f, 1.0f, 4.0f), glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f), 40.0f};
    return scene;
  }
  if (name == "fur") {
    const std::size_t total = std::max<std::size_t>(count, 200);
    ObjectList objects;
    objects.add(displaced_sphere_shape(total / 10, glm::vec3(0.0f), 0.8f, kSeed), objects.add_material(Material{glm::vec3(0.6f)}));
    objects.add(strands_shape(total - objects.triangle_count(), 0.8f, 0.35f, 0.004f, kSeed),
                objects.add_material(Material{glm::vec3(0.8f, 0.6f, 0.4f)}));
    return std::move(objects).finish(label, kWhiteSky, streamed);
  }
  if (name == "default") {
    ObjectList objects;
    objects.add(displaced_sphere_shape(count, glm::vec3(0.0f, 1.15f, 0.0f), 1.0f, kSeed),
                objects.add_material(Material{glm::vec3(0.80f, 0.45f, 0.25f)}));
    objects.add(quad_shape(glm::vec3(-10.0f, 0.0f, 10.0f), glm::vec3(20.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, -20.0f)),
                objects.add_material(Material{glm::vec3(0.65f)}));
    objects.add(quad_shape(glm::vec3(-1.0f, 4.5f, -1.0f), glm::vec3(2.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, 2.0f)),
                objects.add_material(Material{glm::vec3(0.0f), glm::vec3(15.0f)}));
    Scene scene = std::move(objects).finish(label, glm::vec3(0.03f, 0.04f, 0.06f), streamed);
    scene.camera = Camera{glm::vec3(0.0f, 2.4f, 5.8f), glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f), 40.0f};
    return scene;
  }
  if (name == "room") return make_room(label, std::max<std::size_t>(count, 2000), streamed);
  std::string known;
  for (const std::string& builtin : builtin_scene_names()) known += (known.empty() ? "" : ", ") + builtin;
  throw SceneError(fmt::format("{}: unknown builtin scene '{}' (known: {})", label, name, known));
}

}  // namespace wavetrace
