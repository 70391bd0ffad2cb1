// The builtin scenes, composed from the procedural shapes.
#include "scene/builtin_scenes.hpp"

#include <charconv>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "scene/scene_assembly.hpp"
#include "scene/shapes.hpp"

namespace wavetrace {
namespace {

constexpr std::string_view kPrefix = "builtin:";
constexpr std::uint32_t kSeed = 1;
const glm::vec3 kWhiteSky(1.0f);

Scene single_object(std::string name, const TriangleMesh& mesh, const Material& material) {
  SceneAssembly assembly;
  assembly.add(mesh, assembly.add_material(material));
  return std::move(assembly).finish(std::move(name), kWhiteSky);
}

// A closed room (the paper's Cornell box and Sponza play this part): walls, floor and
// ceiling facing inward, an area light under the ceiling, and detailed objects sharing the
// triangle budget. Every ray from inside hits something, so bounces are real work.
Scene make_room(std::string name, std::size_t triangles) {
  const glm::vec3 lower(-4.0f, 0.0f, -4.0f), upper(4.0f, 3.5f, 4.0f);
  const auto share = [&](double fraction) { return std::max<std::size_t>(20, std::size_t(double(triangles) * fraction)); };
  SceneAssembly assembly;
  // Left wall red, right wall green, the rest white, as in a Cornell box.
  assembly.add(make_room_shell(lower, upper, share(0.04)),
               {Material{glm::vec3(0.63f, 0.065f, 0.05f)}, Material{glm::vec3(0.14f, 0.45f, 0.09f)},
                Material{glm::vec3(0.75f)}});
  // Just under the ceiling, facing down: the room stays closed without it.
  assembly.add(make_quad(glm::vec3(-0.8f, upper.y - 0.01f, -1.8f), glm::vec3(1.6f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, 1.6f)),
               assembly.add_material(Material{glm::vec3(0.0f), glm::vec3(17.0f)}));
  assembly.add(translated(make_terrain(share(0.20), 3.2f, 0.35f, kSeed), glm::vec3(-2.0f, 0.3f, -1.6f)),
               assembly.add_material(Material{glm::vec3(0.55f, 0.5f, 0.4f)}));
  assembly.add(make_displaced_sphere(share(0.28), glm::vec3(1.5f, 1.0f, -1.8f), 0.9f, kSeed),
               assembly.add_material(Material{glm::vec3(0.80f, 0.45f, 0.25f)}));
  assembly.add(make_displaced_sphere(share(0.16), glm::vec3(-2.0f, 1.05f, -1.8f), 0.6f, kSeed + 1),
               assembly.add_material(Material{glm::vec3(0.30f, 0.45f, 0.75f)}));
  assembly.add(make_displaced_sphere(share(0.10), glm::vec3(0.1f, 0.42f, 0.3f), 0.4f, kSeed + 2),
               assembly.add_material(Material{glm::vec3(0.75f)}));
  const glm::vec3 fur_center(1.9f, 0.85f, 0.9f);
  const std::size_t fur = share(0.22);
  assembly.add(make_displaced_sphere(fur / 10, fur_center, 0.45f, kSeed + 3),
               assembly.add_material(Material{glm::vec3(0.6f)}));
  assembly.add(translated(make_strands(fur - fur / 10, 0.45f, 0.3f, 0.004f, kSeed), fur_center),
               assembly.add_material(Material{glm::vec3(0.85f, 0.65f, 0.4f)}));
  Scene scene = std::move(assembly).finish(std::move(name), glm::vec3(0.0f));
  scene.camera = Camera{glm::vec3(0.0f, 1.7f, 3.7f), glm::vec3(0.0f, 1.0f, -1.0f), glm::vec3(0.0f, 1.0f, 0.0f), 62.0f};
  scene.enclosure = Bounds3{lower, upper};
  return scene;
}

}  // namespace

bool is_builtin_scene(std::string_view source) { return source.starts_with(kPrefix); }

std::vector<std::string> builtin_scene_names() { return {"sphere", "terrain", "soup", "stadium", "fur", "default", "room"}; }

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

Scene make_builtin_scene(std::string_view source) {
  const std::string_view spec = source.substr(kPrefix.size());
  const std::size_t colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  const std::string label(source);
  const auto count_or = [&](std::size_t fallback) {
    return colon == std::string_view::npos ? fallback : parse_triangle_count(spec.substr(colon + 1), label);
  };
  if (name == "sphere") {
    return single_object(label, make_displaced_sphere(count_or(1000000), glm::vec3(0.0f), 1.0f, kSeed),
                         Material{glm::vec3(0.7f)});
  }
  if (name == "soup") {
    const TriangleMesh sphere = make_displaced_sphere(count_or(1000000), glm::vec3(0.0f), 1.0f, kSeed);
    TriangleMesh soup;
    soup.positions.resize(sphere.triangle_count() * 3);
    soup.triangles.resize(sphere.triangle_count());
    tbb::parallel_for(std::size_t{0}, sphere.triangle_count(), [&](std::size_t t) {
      const auto base = static_cast<std::uint32_t>(3 * t);
      for (int k = 0; k < 3; ++k) soup.positions[base + k] = sphere.positions[sphere.triangles[t][k]];
      soup.triangles[t] = glm::uvec3(base, base + 1, base + 2);
    });
    return single_object(label, soup, Material{glm::vec3(0.7f)});
  }
  if (name == "terrain") {
    return single_object(label, make_terrain(count_or(1000000), 4.0f, 0.6f, kSeed), Material{glm::vec3(0.6f)});
  }
  if (name == "stadium") {
    const std::size_t total = std::max<std::size_t>(count_or(1000000), 32);
    SceneAssembly assembly;
    assembly.add(make_displaced_sphere(total - 12, glm::vec3(0.0f), 1.0f, kSeed),
                 assembly.add_material(Material{glm::vec3(0.7f)}));
    assembly.add(make_inward_box(glm::vec3(-500.0f), glm::vec3(500.0f)), assembly.add_material(Material{glm::vec3(0.5f)}));
    Scene scene = std::move(assembly).finish(label, kWhiteSky);
    scene.camera = Camera{glm::vec3(0.0f, 1.0f, 4.0f), glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f), 40.0f};
    return scene;
  }
  if (name == "fur") {
    const std::size_t total = std::max<std::size_t>(count_or(1000000), 200);
    SceneAssembly assembly;
    assembly.add(make_displaced_sphere(total / 10, glm::vec3(0.0f), 0.8f, kSeed),
                 assembly.add_material(Material{glm::vec3(0.6f)}));
    assembly.add(make_strands(total - assembly.triangle_count(), 0.8f, 0.35f, 0.004f, kSeed),
                 assembly.add_material(Material{glm::vec3(0.8f, 0.6f, 0.4f)}));
    return std::move(assembly).finish(label, kWhiteSky);
  }
  if (name == "default") {
    SceneAssembly assembly;
    assembly.add(make_displaced_sphere(count_or(200000), glm::vec3(0.0f, 1.15f, 0.0f), 1.0f, kSeed),
                 assembly.add_material(Material{glm::vec3(0.80f, 0.45f, 0.25f)}));
    assembly.add(make_quad(glm::vec3(-10.0f, 0.0f, 10.0f), glm::vec3(20.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, -20.0f)),
                 assembly.add_material(Material{glm::vec3(0.65f)}));
    assembly.add(make_quad(glm::vec3(-1.0f, 4.5f, -1.0f), glm::vec3(2.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, 2.0f)),
                 assembly.add_material(Material{glm::vec3(0.0f), glm::vec3(15.0f)}));
    Scene scene = std::move(assembly).finish(label, glm::vec3(0.03f, 0.04f, 0.06f));
    scene.camera = Camera{glm::vec3(0.0f, 2.4f, 5.8f), glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f), 40.0f};
    return scene;
  }
  if (name == "room") return make_room(label, std::max<std::size_t>(count_or(1000000), 2000));
  std::string known;
  for (const std::string& builtin : builtin_scene_names()) known += (known.empty() ? "" : ", ") + builtin;
  throw SceneError(fmt::format("{}: unknown builtin scene '{}' (known: {})", label, name, known));
}

}  // namespace wavetrace
