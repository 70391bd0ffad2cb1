// Saving a built world to sections and loading it back in place.
#include "wavetrace/setup/world_file.hpp"

#include <chrono>
#include <cstddef>
#include <cstring>
#include <sstream>

#include <fmt/format.h>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/memory/section_writer.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"
#include "wavetrace/setup/plan_render.hpp"

namespace wavetrace {
namespace {

// "scene.info", 152 bytes:
//   offset  size  field
//        0     8  triangles, uint64
//        8     8  vertices, uint64
//       16    24  bounds: float lower x, y, z, upper x, y, z
//       40    12  background radiance, float r, g, b
//       52     4  has_camera, uint32 (0 or 1)
//       56    40  camera: position, look_at, up (float x, y, z each), vertical fov degrees (float)
//       96     4  has_enclosure, uint32 (0 or 1)
//      100    24  enclosure: float lower x, y, z, upper x, y, z
//      124     4  zero
//      128     8  degenerate triangles dropped when loaded, uint64
//      136     8  subdivision levels, uint64
//      144     8  non-manifold faces dropped, uint64
struct SavedSceneInfo {
  std::uint64_t triangles, vertices;
  Bounds3 bounds;
  glm::vec3 background;
  std::uint32_t has_camera;
  Camera camera;
  std::uint32_t has_enclosure;
  Bounds3 enclosure;
  std::uint32_t zero;
  std::uint64_t degenerate_dropped, subdivision_levels, non_manifold_faces_dropped;
};
static_assert(sizeof(SavedSceneInfo) == 152 && offsetof(SavedSceneInfo, camera) == 56 &&
              offsetof(SavedSceneInfo, degenerate_dropped) == 128);

// "build.info", 24 bytes: scene seconds (double), build seconds (double), the build's peak
// resident bytes (uint64, VmHWM).
static_assert(sizeof(WorldBuildInfo) == 24);

// "proxy.info", 48 bytes:
//   offset  size  field
//        0     4  method, uint32 (1: cluster, 2: stochastic)
//        4     4  surface tolerance, float (Proxy::surface_tolerance)
//        8     8  triangles, uint64
//       16     8  simplify seconds, double
//       24    24  quality on test rays: hit agreement, hit overlap, mean distance error (doubles)
struct SavedProxyInfo {
  std::uint32_t method;
  float surface_tolerance;
  std::uint64_t triangles;
  double simplify_seconds;
  double hit_agreement, hit_overlap, mean_distance_error;
};
static_assert(sizeof(SavedProxyInfo) == 48);
static_assert(sizeof(LightSampler::EmissiveTriangle) == 64);

// "scene.materials", 24 bytes a material: albedo, emission (float x, y, z each, offsets 0
// and 12). Worlds saved before mirrors and glass hold only these: all diffuse.
struct SavedMaterialColors {
  glm::vec3 albedo, emission;
};
static_assert(sizeof(SavedMaterialColors) == 24);
// "scene.material_surfaces", 8 bytes a material, in the same order: Surface (uint32,
// 0 diffuse, 1 mirror, 2 glass), ior (float).
struct SavedMaterialSurface {
  std::uint32_t surface;
  float ior;
};
static_assert(sizeof(SavedMaterialSurface) == 8);

std::span<const std::byte> text_bytes(const std::string& text) { return std::as_bytes(std::span(text.data(), text.size())); }

std::string text_of(const SectionFile& file, std::string_view name) {
  const std::span<const std::byte> bytes = file.bytes(name);
  return std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

void add_mesh(SectionWriter& out, const std::string& prefix, const TriangleMesh& mesh) {
  out.add_array(prefix + "positions", std::span<const glm::vec3>(mesh.positions));
  out.add_array(prefix + "triangles", std::span<const glm::uvec3>(mesh.triangles));
}

TriangleMesh read_mesh(const SectionFile& file, const std::string& prefix) {
  TriangleMesh mesh;
  const auto positions = file.array<glm::vec3>(prefix + "positions");
  const auto triangles = file.array<glm::uvec3>(prefix + "triangles");
  mesh.positions.reserve(positions.size() + 1);  // the spare vertex validate_and_clean keeps
  mesh.positions.assign(positions.begin(), positions.end());
  mesh.triangles.assign(triangles.begin(), triangles.end());
  for (const glm::uvec3& triangle : mesh.triangles) {
    if (triangle.x >= positions.size() || triangle.y >= positions.size() || triangle.z >= positions.size()) {
      file.fail(prefix + "triangles", "names a vertex that does not exist");
    }
  }
  return mesh;
}

// The proxy's accelerator as the world was built with it: the build's options, of the type
// proxy.accel named.
AcceleratorOptions saved_proxy_accelerator(const Config& settings, int threads) {
  AcceleratorOptions options = accelerator_options(settings);
  options.type = settings.text("proxy.accel");
  options.embree.threads = threads;
  return options;
}

}  // namespace

std::optional<PagingRequest> world_paging(const RenderPlan& plan) {
  if (!plan.memory.file_backing) return std::nullopt;
  return PagingRequest{plan.memory.page_bytes, *plan.memory.budget, kFilePagerClients, plan.memory.page_mapping};
}

FileHolding world_holding(const RenderPlan& plan) {
  return plan.memory.copy_world ? FileHolding::copied : FileHolding::mapped;
}

bool is_world_file(const std::string& path) { return path.size() > 4 && path.compare(path.size() - 4, 4, ".wtw") == 0; }

void save_world(const std::string& path, const Scene& scene, const LightSampler& lights, const Accelerator& accelerator,
                const std::string& type, const Proxy* proxy, const Config& settings, const WorldBuildInfo& info) {
  SectionWriter out(path);
  save_world(out, scene, lights, accelerator, type, proxy, settings, info);
}

void save_world(SectionWriter& out, const Scene& scene, const LightSampler& lights, const Accelerator& accelerator,
                const std::string& type, const Proxy* proxy, const Config& settings, const WorldBuildInfo& info) {
  out.add_value("world.kind", saved_kind("world", kWorldFileVersion));
  out.add("scene.name", text_bytes(scene.name));
  SavedSceneInfo scene_info{};
  scene_info.triangles = scene.triangle_count;
  scene_info.vertices = scene.vertex_count;
  scene_info.bounds = scene.bounds;
  scene_info.background = scene.background;
  scene_info.has_camera = scene.camera.has_value();
  scene_info.camera = scene.camera.value_or(Camera{});
  scene_info.has_enclosure = scene.enclosure.has_value();
  scene_info.enclosure = scene.enclosure.value_or(Bounds3{});
  scene_info.degenerate_dropped = scene.cleanup.degenerate_dropped;
  scene_info.subdivision_levels = scene.subdivision_levels;
  scene_info.non_manifold_faces_dropped = scene.non_manifold_faces_dropped;
  out.add_value("scene.info", scene_info);
  std::vector<SavedMaterialColors> colors;
  std::vector<SavedMaterialSurface> surfaces;
  for (const Material& material : scene.materials) {
    colors.push_back({material.albedo, material.emission});
    surfaces.push_back({static_cast<std::uint32_t>(material.surface), material.ior});
  }
  out.add_array("scene.materials", std::span<const SavedMaterialColors>(colors));
  out.add_array("scene.material_surfaces", std::span<const SavedMaterialSurface>(surfaces));
  out.add_array("scene.material_runs.first", scene.material_runs.firsts());
  out.add_array("scene.material_runs.material", scene.material_runs.materials());
  out.add_array("scene.lights", lights.triangles());
  out.add_array("scene.light_cdf", lights.cumulative());

  std::string settings_text;
  for (const auto& [key, value] : settings.values()) {
    if (key.starts_with("accel.") || key.starts_with("build.") || key.starts_with("proxy.")) {
      settings_text += settings.assignment(key) + "\n";
    }
  }
  out.add("build.settings", text_bytes(settings_text));
  out.add("build.notes", text_bytes(accelerator.build_notes()));
  out.add_value("build.info", info);

  if (saves_structure(type)) {
    accelerator.save(out, kWorldAcceleratorPrefix);
  } else {
    if (scene.mesh.triangles.empty()) {
      throw std::logic_error(fmt::format("saving a '{}' world needs the scene's mesh, which is rebuilt from", type));
    }
    out.add_value(std::string(kWorldAcceleratorPrefix) + "kind", saved_kind(type, 0));
    add_mesh(out, "geometry.", scene.mesh);
    out.add_array("geometry.materials", std::span<const std::uint32_t>(scene.mesh.material_of_triangle));
  }
  if (proxy != nullptr) {
    add_mesh(out, "proxy.", proxy->mesh());
    const ProxyReport& report = proxy->report();
    const SavedProxyInfo proxy_info{static_cast<std::uint32_t>(report.method), proxy->surface_tolerance(),
                                    report.triangles, report.simplify_seconds, report.quality.hit_agreement,
                                    report.quality.hit_overlap, report.quality.mean_distance_error};
    out.add_value("proxy.info", proxy_info);
  }
  out.finish();
}

std::unique_ptr<LoadedWorld> load_world(const std::string& path, const std::optional<PagingRequest>& paging, int threads,
                                        CheckedPages checked, FileHolding holding) {
  const auto start = std::chrono::steady_clock::now();
  auto loaded = std::make_unique<LoadedWorld>();
  LoadedWorld& world = *loaded;
  world.file = SectionFile::open(path, paging, checked, holding);
  const SectionFile& file = *world.file;
  SectionLoader(world.file, "world.").expect_kind("world", kWorldFileVersion);

  Scene& scene = world.scene;
  scene.name = text_of(file, "scene.name");
  const auto info = file.value<SavedSceneInfo>("scene.info");
  scene.triangle_count = info.triangles;
  scene.vertex_count = info.vertices;
  scene.bounds = info.bounds;
  scene.background = info.background;
  if (info.has_camera) scene.camera = info.camera;
  if (info.has_enclosure) scene.enclosure = info.enclosure;
  scene.cleanup.degenerate_dropped = info.degenerate_dropped;
  scene.subdivision_levels = info.subdivision_levels;
  scene.non_manifold_faces_dropped = info.non_manifold_faces_dropped;
  for (const SavedMaterialColors& colors : file.array<SavedMaterialColors>("scene.materials")) {
    scene.materials.push_back(Material{colors.albedo, colors.emission});
  }
  if (file.has("scene.material_surfaces")) {
    const auto surfaces = file.array<SavedMaterialSurface>("scene.material_surfaces");
    if (surfaces.size() != scene.materials.size()) {
      file.fail("scene.material_surfaces", "lists a different number of materials than scene.materials");
    }
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
      if (surfaces[i].surface > static_cast<std::uint32_t>(Surface::glass) || !(surfaces[i].ior >= 1.0f)) {
        file.fail("scene.material_surfaces", fmt::format("material {} has an unknown surface or an ior under 1", i));
      }
      scene.materials[i].surface = static_cast<Surface>(surfaces[i].surface);
      scene.materials[i].ior = surfaces[i].ior;
    }
  }
  try {
    scene.material_runs = MaterialRuns::from_runs(file.array<std::uint64_t>("scene.material_runs.first"),
                                                  file.array<std::uint32_t>("scene.material_runs.material"));
    const auto lights = file.array<LightSampler::EmissiveTriangle>("scene.lights");
    const auto cdf = file.array<float>("scene.light_cdf");
    world.lights = std::make_unique<LightSampler>(std::vector(lights.begin(), lights.end()), std::vector(cdf.begin(), cdf.end()));
  } catch (const std::invalid_argument& error) {
    file.fail("scene.material_runs", fmt::format("or scene.lights is inconsistent: {}", error.what()));
  }
  for (const std::uint32_t material : scene.material_runs.materials()) {
    if (material >= scene.materials.size()) file.fail("scene.material_runs.material", "names a material that does not exist");
  }

  std::istringstream settings(text_of(file, "build.settings"));
  for (std::string line; std::getline(settings, line);) {
    if (line.empty()) continue;
    try {
      world.settings.restore(line);
    } catch (const ConfigError& error) {
      file.fail("build.settings", fmt::format("holds a setting this build does not know: {}", error.what()));
    }
  }
  world.type = world.settings.text("accel.type");
  world.notes = text_of(file, "build.notes");
  world.build = file.value<WorldBuildInfo>("build.info");

  if (saves_structure(world.type)) {
    SectionLoader accel(world.file, kWorldAcceleratorPrefix);
    world.accelerator = load_accelerator(accel);
  } else {
    // Embree and the grids cannot be written: rebuilt, with the settings they were built with.
    SectionLoader accel(world.file, kWorldAcceleratorPrefix);
    accel.expect_kind(world.type, 0);
    scene.mesh = read_mesh(file, "geometry.");
    const auto material_of_triangle = file.array<std::uint32_t>("geometry.materials");
    scene.mesh.material_of_triangle.assign(material_of_triangle.begin(), material_of_triangle.end());
    if (scene.mesh.triangle_count() != scene.triangle_count ||
        (!material_of_triangle.empty() && material_of_triangle.size() != scene.triangle_count)) {
      file.fail("geometry.triangles", "does not hold the scene's triangles");
    }
    AcceleratorOptions options = accelerator_options(world.settings);
    options.embree.threads = threads;
    world.accelerator = make_accelerator(scene.mesh, options);
    world.rebuilt = true;
  }
  if (file.has("proxy.info")) {
    const auto proxy_info = file.value<SavedProxyInfo>("proxy.info");
    ProxyReport report;
    report.method = static_cast<ProxyMethod>(proxy_info.method);
    report.triangles = proxy_info.triangles;
    report.simplify_seconds = proxy_info.simplify_seconds;
    report.quality = {proxy_info.hit_agreement, proxy_info.hit_overlap, proxy_info.mean_distance_error};
    world.proxy = std::make_unique<Proxy>(read_mesh(file, "proxy."), scene.bounds, proxy_info.surface_tolerance, report,
                                          saved_proxy_accelerator(world.settings, threads));
  }
  world.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return loaded;
}

void coarsen_world_proxy(LoadedWorld& world, double share, int threads, ProxyJudge judge) {
  if (!world.proxy) return;
  const std::size_t target = proxy_target_triangles(share, world.scene.triangle_count);
  // Clustering lands within about 15% of its target: a proxy that near is left as it is.
  if (world.proxy->report().triangles * 4 <= target * 5) return;
  world.proxy = std::make_unique<Proxy>(*world.proxy, target, saved_proxy_accelerator(world.settings, threads),
                                        judge == ProxyJudge::whole_world ? world.accelerator.get() : nullptr);
}

}  // namespace wavetrace
