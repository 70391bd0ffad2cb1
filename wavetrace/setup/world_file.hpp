// Saved worlds (.wtw): a built world written once by `wavetrace build` and rendered many
// times without rebuilding. The file is a section file (memory/section_file_format.hpp);
// its sections, all little-endian:
//
//   world.kind                  SavedKind (accel/section_archive.hpp): "world", kWorldFileVersion
//   scene.name                  bytes: the scene's name, UTF-8
//   scene.info                  SavedSceneInfo (below)
//   scene.materials             24 bytes a material: albedo, emission (float x, y, z each)
//   scene.material_surfaces     8 bytes a material: Surface (uint32), ior (float); absent in
//                               worlds saved before mirrors and glass (all diffuse)
//   scene.material_runs.first   uint64 a run: its first triangle (MaterialRuns)
//   scene.material_runs.material  uint32 a run: its material
//   scene.lights                64 bytes a light (LightSampler::EmissiveTriangle)
//   scene.light_cdf             float a light: the normalized running sum of power
//   build.settings              bytes: the accel.*, build.* and proxy.* keys the world was
//                               built with, one "section.key=value" line each
//   build.notes                 bytes: the accelerator's build notes
//   build.info                  SavedBuildInfo (below)
//   accel/...                   the accelerator's own sections (load_accelerator), or only
//                               accel/kind naming a type that is rebuilt from geometry.*
//   geometry.positions          float x, y, z a vertex   } only for types rebuilt at load
//   geometry.triangles          uint32 x3 a triangle      } (embree, the grids): the mesh
//   geometry.materials          uint32 a triangle         } they need
//   proxy.positions, proxy.triangles   the simplified mesh, as geometry.*  } when the
//   proxy.info                  SavedProxyInfo (below)                     } world has a proxy
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/memory/section_file.hpp"
#include "wavetrace/memory/section_writer.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/scene.hpp"
#include "wavetrace/setup/config.hpp"

namespace wavetrace {

inline constexpr std::uint32_t kWorldFileVersion = 1;

// True for a path a world file is named by (".wtw").
bool is_world_file(const std::string& path);

struct WorldBuildInfo {
  double scene_seconds = 0.0;  // loading or generating the scene
  double build_seconds = 0.0;  // building the accelerator (and the proxy)
  std::uint64_t peak_rss_bytes = 0;
};

// Writes `path`. `settings` holds the accel, build and proxy keys used; `accelerator` is
// saved in place when its type saves_structure, else the scene's mesh (which must then be
// present) is saved for a rebuild at load. Throws std::runtime_error naming the file.
void save_world(const std::string& path, const Scene& scene, const LightSampler& lights, const Accelerator& accelerator,
                const std::string& type, const Proxy* proxy, const Config& settings, const WorldBuildInfo& info);
// The same into a writer opened before the build, which may hold the accelerator's chunks
// already (ChunkStream under "accel/", the prefix the world's accelerator is saved under);
// finishes it.
inline constexpr const char* kWorldAcceleratorPrefix = "accel/";
void save_world(SectionWriter& out, const Scene& scene, const LightSampler& lights, const Accelerator& accelerator,
                const std::string& type, const Proxy* proxy, const Config& settings, const WorldBuildInfo& info);

// Held by pointer: a rebuilt Embree refers to `scene.mesh` where it lies.
struct LoadedWorld {
  LoadedWorld() = default;
  LoadedWorld(const LoadedWorld&) = delete;
  LoadedWorld& operator=(const LoadedWorld&) = delete;

  std::shared_ptr<const SectionFile> file;
  Scene scene;  // described; its mesh only where the accelerator was rebuilt from it
  std::unique_ptr<LightSampler> lights;
  std::unique_ptr<Accelerator> accelerator;
  std::unique_ptr<Proxy> proxy;  // null when the world was saved without one
  std::string type;              // accel.type it was built with
  Config settings;               // the build's accel, build and proxy keys
  std::string notes;
  WorldBuildInfo build;
  bool rebuilt = false;          // the accelerator was built now, from the saved geometry
  double seconds = 0.0;          // opening, checking and loading (rebuild included)
};

// The paging a plan asks for: real paging under memory.budget when memory.backing = file.
struct RenderPlan;
std::optional<PagingRequest> world_paging(const RenderPlan& plan);
// How a plan asks a world file not paged to be held: copied when memory.backing = copy.
FileHolding world_holding(const RenderPlan& plan);

// Maps `path` (copies it, as `holding` asks, or pages it under `paging`) and loads the world
// in place. `threads` is for a rebuilt Embree; `checked` says what the load's checks leave
// resident (section_file.hpp). Throws SectionFileError naming the file and its problem.
std::unique_ptr<LoadedWorld> load_world(const std::string& path, const std::optional<PagingRequest>& paging = std::nullopt,
                                        int threads = 0, CheckedPages checked = CheckedPages::kept,
                                        FileHolding holding = FileHolding::mapped);

// Simplifies the world's proxy again where it holds more than about `share` of the scene's
// triangles (proxy.share = auto in core: a world is saved with the paper's 2%); its quality is
// measured against the world's accelerator, or against the saved proxy (ProxyJudge::saved_proxy:
// a data-parallel rank, which touches only the chunks it answers). `threads` as for load_world.
enum class ProxyJudge { whole_world, saved_proxy };
void coarsen_world_proxy(LoadedWorld& world, double share, int threads, ProxyJudge judge = ProxyJudge::whole_world);

}  // namespace wavetrace
