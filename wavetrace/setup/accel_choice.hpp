// accel.type = auto: the fastest accelerator that fits a memory budget and meets an error
// bound, never one on its known failure case; and error bounds in pixels (accel.max_error,
// accel.hmq.epsilon = pixel), resolved against the camera before anything is built.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/scene/camera.hpp"
#include "wavetrace/scene/triangle_source.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/stages/generate.hpp"

namespace wavetrace {

// What the config asks of the choice (accel.type, accel.memory_budget, accel.max_error,
// accel.hmq.epsilon = pixel); read by the key table (plan_render.hpp: accel_goal).
struct AccelGoal {
  bool automatic = false;                  // accel.type = auto
  std::string memory_budget = "available";  // as given
  std::optional<double> max_error;         // scene units; none: half a pixel's footprint
  bool hmq_epsilon_pixel = false;          // accel.hmq.epsilon = pixel
  bool operator==(const AccelGoal&) const = default;
};

// "available" (what the OS reports available now, less 10%), "50%" (of that available
// memory) or a size ("8GB", "512MiB"); throws ConfigError naming accel.memory_budget.
std::size_t resolve_accel_memory_budget(const std::string& text);

// What the choice needs to know of a scene, from one pass over its triangles.
struct SceneTraits {
  std::size_t triangles = 0;
  std::size_t vertices = 0;  // summed over the pass's chunks (a vertex shared across two counts twice)
  Bounds3 bounds;
  // 3 x triangles / vertices: about 6 on a closed mesh, 1 on a soup, whose strips would be
  // one triangle each (Ray-Strips' failure case).
  double triangles_per_vertex = 0.0;
  // On the cells the hashed grid would take: the triangles sharing an average triangle's
  // cell (sum of n^2 over sum of n, by triangle centroid; corrected for sampling past
  // kTraitSampleLimit). A few on an even surface; the whole small object on a stadium,
  // where a ray entering that cell tests all of them (the grids' failure case).
  double triangles_per_grid_cell = 0.0;
  // On the same cells: how many an average triangle overlaps (the hashed grid's list entries a
  // triangle, which its bytes follow), and how many its box does (the paper's lists,
  // accel.grid.bounding_box_lists).
  double grid_entries_per_triangle = 0.0;
  double grid_box_entries_per_triangle = 0.0;
  // The mesh read whole: 12 bytes a vertex, 12 of indices and 4 of material a triangle.
  double mesh_bytes_per_triangle = 0.0;
  // The nearest distance from the camera to a triangle that may lie in view (not culled by
  // the view frustum; occlusion ignored, so never farther than the nearest surface seen).
  std::optional<double> nearest_in_view;
  // Built in chunks of the options' chunk_triangles (runs of the source's order, cut at its
  // objects): the chunk boxes containing an average triangle's centroid; 1 for chunks that
  // tile the scene, the chunk count where every chunk spans the whole object (a subdivided
  // scan's faces). A ray near that point may descend into each of them; auto's estimate of
  // a chunked structure's speed is divided by chunk_slowdown(overlap) (accel_choice.cpp).
  double chunk_overlap = 1.0;
  std::size_t chunks = 1;
  std::vector<std::size_t> chunk_sizes;  // triangles, largest first (the chunked builds at once)
  // The same measures for smaller chunks, which auto falls back to where a chunked candidate
  // does not fit in chunks of the options' size (its build holds smaller chunks at once):
  // each a quarter of the one before, measured in the same pass, largest first.
  struct Chunking {
    std::size_t chunk_triangles = 0;
    double overlap = 1.0;
    std::size_t chunks = 1;
    std::vector<std::size_t> sizes;  // largest first
  };
  std::vector<Chunking> smaller_chunkings;
};
// The smallest chunks auto falls back to: a chunk's fixed costs (its box in the top BVH, a
// round of the chunked walk) outweigh its build's temporaries below this.
inline constexpr std::size_t kSmallestAutoChunk = std::size_t{1} << 16;
inline constexpr std::size_t kTraitSampleLimit = std::size_t{1} << 20;
// A mean over a grid cell past this is crowded; triangles per vertex under this, a soup.
inline constexpr double kCrowdedGridCell = 64.0;
inline constexpr double kSoupTrianglesPerVertex = 2.0;
// What auto counts besides the accelerator and the mesh: the process (code, TBB and Embree,
// batches, lights: a 64x48 render of builtin:room:20k peaks at 16 MB, and 1920x1080 adds 36
// bytes a pixel: film, image and its preview), and the chunks the chunked builder builds at
// once (one per worker thread).
struct AutoAllowance {
  std::size_t process_bytes = 0;
  std::size_t builds_at_once = 1;
};
inline constexpr std::size_t kAutoProcessBaseBytes = 32000000;
inline constexpr std::size_t kAutoProcessBytesPerPixel = 48;
AutoAllowance auto_allowance(const ImageSpec& image);
// A mesh read whole, on a closed mesh (2 triangles a vertex): positions, 32-bit indices and a
// material per triangle (docs/memory.md, "Memory at scale"); check_scene_fits counts it before any
// pass (auto measures it: SceneTraits::mesh_bytes_per_triangle).
inline constexpr double kWholeMeshBytesPerTriangle = 22.0;

// The pass; `chunk_triangles` as the chunked builder would cut the scene (0: never chunked);
// `camera` and `image` (for the aspect) when the nearest distance in view is wanted; with
// `smaller_chunkings`, the chunkings of a quarter, a sixteenth ... of chunk_triangles down to
// kSmallestAutoChunk are measured too.
SceneTraits measure_scene_traits(const TriangleSource& source, std::size_t chunk_triangles = 0,
                                 const Camera* camera = nullptr, const ImageSpec* image = nullptr,
                                 bool smaller_chunkings = false);

// Half the footprint of a pixel (at the image's centre, the narrowest) at `distance`.
double half_pixel_footprint(const Camera& camera, const ImageSpec& image, double distance);

// One candidate of the choice.
struct AccelCandidate {
  std::string spec;  // as --accel names it, e.g. "hmq:width=8:epsilon=0.0012"
  AcceleratorOptions options;
  // Its speed against robust Embree's on this scene: the median measured on the report's
  // scenes, over the chunk overlap when it would be built in chunks.
  double estimated_speed = 0.0;
  bool chunked = false;
  double estimated_bytes = 0.0;  // peak: structure, the mesh, its build's temporaries, the process
  bool fits = false;
  bool meets_error = false;
  std::optional<std::string> failure_case;  // the scene is this method's known failure case
  bool chosen = false;
  std::string reason;  // why it was chosen or passed over
};

struct AccelChoice {
  AcceleratorOptions options;  // the chosen accelerator's
  std::string spec;
  std::size_t budget_bytes = 0;
  AutoAllowance allowance;
  double max_error = 0.0;                  // scene units
  std::optional<double> pixel_distance;    // the nearest distance in view, when pixel was asked
  SceneTraits traits;
  std::vector<AccelCandidate> candidates;  // every one tried, in order
  std::string summary;                     // one line: what was chosen and why
};

// Of the candidates that fit `budget_bytes`, meet `max_error` and whose failure case the scene
// is not, keeps the one of the highest estimated speed; `base` supplies every other option.
// Throws ConfigError naming each candidate's reason when none qualifies.
AccelChoice choose_accelerator(const SceneTraits& traits, std::size_t budget_bytes, double max_error,
                               const AcceleratorOptions& base, bool streamed_source, const AutoAllowance& allowance);

nlohmann::json to_json(const AccelChoice& choice);

// Whether accel.hmq.epsilon = pixel applies to the type the options name (it bounds hmq's error).
bool pixel_epsilon_applies(const AcceleratorOptions& options, const AccelGoal& goal);

// The accelerator a plan's goal resolves to on this scene: `options` unchanged when nothing
// is automatic, HMQ's epsilon set from the pixel footprint for hmq.epsilon = pixel, or the
// choice for accel.type = auto (returned too, for the report).
struct ResolvedAccelerator {
  AcceleratorOptions options;
  std::optional<AccelChoice> choice;
  std::optional<double> pixel_epsilon;   // half a pixel's footprint, when pixel was asked
  std::optional<double> pixel_distance;  // at this distance: the nearest surface in view
};
// One line: what auto chose and why, or what a pixel bound came to; empty when neither.
std::string resolution_summary(const ResolvedAccelerator& resolved);
ResolvedAccelerator resolve_accelerator(const AcceleratorOptions& options, const AccelGoal& goal,
                                        const TriangleSource& source, const Camera& camera, const ImageSpec& image,
                                        bool streamed_source);

}  // namespace wavetrace
