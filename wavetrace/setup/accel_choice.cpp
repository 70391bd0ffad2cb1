// accel.type = auto: one pass over the scene's triangles (connectivity, crowding on the
// hashed grid's cells, the overlap of its chunks, the nearest surface in view), then the
// fastest candidate by estimate that fits and meets the bound.
#include "wavetrace/setup/accel_choice.hpp"

#include <algorithm>
#include <atomic>
#include <functional>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <glm/trigonometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include "wavetrace/accel/chunked/chunked_accelerator.hpp"
#include "wavetrace/accel/grid/hashed_grid.hpp"
#include "wavetrace/kernels/triangle_cell_runs.hpp"
#include "wavetrace/accel/hmq/global_grid.hpp"
#include "wavetrace/kernels/triangle_distance.hpp"
#include "wavetrace/memory/simulated_pager.hpp"
#include "wavetrace/memory/process_memory.hpp"

namespace wavetrace {
namespace {

// Triangles extracted at once: the pass's own memory stays small beside what it estimates.
constexpr std::size_t kTraitChunk = std::size_t{1} << 18;
// Centroids tested against every chunk box: enough for the mean to two digits.
constexpr std::size_t kOverlapSamples = std::size_t{1} << 16;

// The view frustum in camera space: a point is (right, up, forward) from the eye.
struct ViewFrustum {
  glm::vec3 eye, right, up, forward;
  float tan_x = 1.0f, tan_y = 1.0f;

  ViewFrustum(const Camera& camera, float aspect)
      : eye(camera.position), forward(glm::normalize(camera.look_at - camera.position)) {
    right = glm::normalize(glm::cross(forward, camera.up));
    up = glm::cross(right, forward);
    tan_y = std::tan(0.5f * glm::radians(camera.vertical_fov_degrees));
    tan_x = tan_y * aspect;
  }
  // False only when all three corners lie beyond one plane of the frustum (behind the eye,
  // or past one side): such a triangle cannot be seen; others may be.
  bool may_see(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) const {
    glm::vec3 local[3];
    const glm::vec3 corners[3] = {a - eye, b - eye, c - eye};
    for (int k = 0; k < 3; ++k) {
      local[k] = {glm::dot(corners[k], right), glm::dot(corners[k], up), glm::dot(corners[k], forward)};
    }
    const auto all = [&](auto outside) { return outside(local[0]) && outside(local[1]) && outside(local[2]); };
    if (all([](const glm::vec3& p) { return p.z <= 0.0f; })) return false;
    if (all([&](const glm::vec3& p) { return p.x > p.z * tan_x; })) return false;
    if (all([&](const glm::vec3& p) { return -p.x > p.z * tan_x; })) return false;
    if (all([&](const glm::vec3& p) { return p.y > p.z * tan_y; })) return false;
    if (all([&](const glm::vec3& p) { return -p.y > p.z * tan_y; })) return false;
    return true;
  }
};

std::string gigabytes(double bytes) {
  return bytes < 1e9 ? fmt::format("{:.1f} MB", bytes * 1e-6) : fmt::format("{:.2f} GB", bytes * 1e-9);
}

// The hashed grid's cells and lists, its mesh apart: a triangle index per cell it overlaps
// (its box overlaps, with the paper's lists) and the hash's slots. Measured (mlgrid, bytes a
// triangle against entries a triangle), boxes: sphere:1M 25.7 at 4.5, bunny00 subdivided twice
// 22.6 at 3.8, room:1M 47.6 at 9.4, room:8M 117.6 at 27.4 (its strands' boxes span many
// cells); the cells a triangle overlaps: room:8M 30.3 at 5.6. About 8 + 4 x entries, with a margin.
constexpr double kGridBytesPerTriangle = 10.0;
constexpr double kGridBytesPerEntry = 4.4;

// Ray-Strips' bytes and its stripifier's temporaries grow as its chunks share fewer edges:
// in chunks, both are scaled by this over the triangles a vertex the pass saw (in its runs of
// 256k, as a chunked build's), 1 on the closed builtins (room 5.5, sphere 5.9); a whole
// build's connectivity is the whole mesh's, which those runs understate. Measured on bunny00
// subdivided twice in chunks of an eighth, whose faces come in no spatial order (2.2): 54
// bytes a triangle against 14 on room and sphere, and 650 of temporaries a chunk triangle
// against 180; the scale gives 2.5x of each, short of the 3.7x measured (docs/accelerators.md).
constexpr double kConnectedTrianglesPerVertex = 5.5;

// How much slower a structure traces built in chunks whose boxes overlap so (SceneTraits::
// chunk_overlap), fitted to `bench report`'s chunked 8-wide hmq, raystrips and bvh against
// whole ones (chunks of an eighth): room 1.22x at overlap 2.96, sphere 1.5x at 3.44, the
// subdivided bunny 4.0x at 8. A square: a ray descends into more chunks, and in each it
// tests more before a hit culls the rest.
double chunk_slowdown(double overlap) { return 1.0 + 0.065 * (overlap - 1.0) * (overlap - 1.0); }

AccelCandidate make_candidate(const AcceleratorType& type, const AcceleratorOptions& base, double max_error) {
  AccelCandidate candidate;
  candidate.options = base;
  candidate.options.type = std::string(type.name);
  type.automatic.set_up(candidate.options, max_error);
  candidate.spec = type.automatic.spec(max_error);
  return candidate;
}

// The candidates, fastest first: the types whose row gives auto a speed (the registry's
// rows say which are not candidates, and why).
std::vector<const AcceleratorType*> candidate_types() {
  std::vector<const AcceleratorType*> types;
  for (const AcceleratorType& type : accelerator_types()) {
    if (type.automatic.relative_speed > 0.0) types.push_back(&type);
  }
  std::stable_sort(types.begin(), types.end(), [](const AcceleratorType* a, const AcceleratorType* b) {
    return a->automatic.relative_speed > b->automatic.relative_speed;
  });
  return types;
}

}  // namespace

std::size_t resolve_accel_memory_budget(const std::string& text) {
  const std::size_t available = available_memory_bytes();
  if (text == "available") {
    if (available == 0) throw ConfigError("accel.memory_budget = 'available': the OS reports no available memory; give a size");
    return static_cast<std::size_t>(0.9 * double(available));
  }
  MemoryBudget budget;
  try {
    budget = parse_memory_budget(text);
  } catch (const std::invalid_argument& error) {
    throw ConfigError(fmt::format("accel.memory_budget: {}", error.what()));
  }
  if (!budget.is_share) return budget.bytes;
  if (available == 0) {
    throw ConfigError(fmt::format("accel.memory_budget = '{}': the OS reports no available memory to take a share of", text));
  }
  return static_cast<std::size_t>(budget.share * double(available));
}

AutoAllowance auto_allowance(const ImageSpec& image) {
  return {kAutoProcessBaseBytes + kAutoProcessBytesPerPixel * std::size_t(image.width) * std::size_t(image.height),
          static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()))};
}

SceneTraits measure_scene_traits(const TriangleSource& source, std::size_t chunk_triangles, const Camera* camera,
                                 const ImageSpec* image, bool smaller_chunkings) {
  SceneTraits traits;
  traits.triangles = source.triangle_count();
  traits.bounds = source.bounds();
  if (traits.triangles == 0) return traits;
  const GridResolution grid = hashed_grid_resolution(traits.bounds, traits.triangles, HashedGridOptions{});
  const glm::dvec3 cell_size = grid.size / glm::dvec3(grid.cells);
  const std::size_t stride = (traits.triangles + kTraitSampleLimit - 1) / kTraitSampleLimit;
  std::optional<ViewFrustum> view;
  if (camera != nullptr && image != nullptr) view.emplace(*camera, float(image->width) / float(image->height));

  std::vector<std::uint64_t> cells;
  cells.reserve(traits.triangles / stride + 1);
  // The cells the sampled triangles overlap, and those their boxes do (grown by the slack the
  // grid's build grows them by).
  std::atomic<std::uint64_t> cells_spanned{0}, box_cells_spanned{0};
  const CellGridFrame frame{glm::dvec3(traits.bounds.lower), cell_size, cell_size * 1e-3};
  // Plan 0 in chunks of chunk_triangles, then each smaller chunking asked for (an empty plan:
  // never chunked at that size).
  std::vector<std::size_t> plan_sizes = {chunk_triangles};
  if (smaller_chunkings && chunk_triangles > 0) {
    for (std::size_t size = chunk_triangles / 4; size >= kSmallestAutoChunk && size >= kMinChunkTriangles; size /= 4) {
      plan_sizes.push_back(size);
    }
  }
  std::vector<std::vector<ChunkRange>> plans;
  for (const std::size_t size : plan_sizes) {
    plans.push_back(size > 0 && traits.triangles > size ? plan_chunks(source.object_starts(), traits.triangles, size)
                                                        : std::vector<ChunkRange>{});
  }
  std::vector<std::vector<Bounds3>> plan_boxes;
  for (const std::vector<ChunkRange>& plan : plans) plan_boxes.emplace_back(plan.size());
  const bool any_chunks = std::any_of(plans.begin(), plans.end(), [](const auto& plan) { return !plan.empty(); });
  std::vector<glm::vec3> centroids;  // a sample, to count the chunk boxes around each
  const std::size_t centroid_stride = std::max<std::size_t>(1, traits.triangles / kOverlapSamples);
  double nearest = std::numeric_limits<double>::infinity();
  // Extraction is serial (a streamed source generates its chunks in order); each chunk's
  // triangles are measured in parallel.
  for (std::size_t first = 0; first < traits.triangles; first += kTraitChunk) {
    const std::size_t count = std::min(kTraitChunk, traits.triangles - first);
    const TriangleMesh chunk = source.extract(first, count);
    traits.vertices += chunk.vertex_count();
    const std::size_t first_sample = (stride - first % stride) % stride;
    const std::size_t samples = first_sample < count ? (count - first_sample + stride - 1) / stride : 0;
    const std::size_t filled = cells.size();
    cells.resize(filled + samples);
    const auto cell_index = [&](double coordinate, int axis) {
      const double index = std::floor((coordinate - double(traits.bounds.lower[axis])) / cell_size[axis]);
      return static_cast<std::uint64_t>(std::clamp(index, 0.0, double(grid.cells[axis] - 1)));
    };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, samples), [&](const tbb::blocked_range<std::size_t>& range) {
      std::uint64_t overlapped = 0, box_overlapped = 0;
      for (std::size_t s = range.begin(); s != range.end(); ++s) {
        const glm::uvec3 t = chunk.triangles[first_sample + s * stride];
        const glm::dvec3 a(chunk.positions[t.x]), b(chunk.positions[t.y]), c(chunk.positions[t.z]);
        const glm::dvec3 centroid = (a + b + c) / 3.0;
        const glm::dvec3 lower = glm::min(a, glm::min(b, c)), upper = glm::max(a, glm::max(b, c));
        glm::u64vec3 cell;
        glm::uvec3 box_lower, box_upper;
        std::uint64_t spanned = 1;
        for (int axis = 0; axis < 3; ++axis) {
          cell[axis] = cell_index(centroid[axis], axis);
          box_lower[axis] = std::uint32_t(cell_index(lower[axis] - frame.slack[axis], axis));
          box_upper[axis] = std::uint32_t(cell_index(upper[axis] + frame.slack[axis], axis));
          spanned *= box_upper[axis] - box_lower[axis] + 1;
        }
        cells[filled + s] = (cell.z * grid.cells.y + cell.y) * grid.cells.x + cell.x;
        box_overlapped += spanned;
        for_each_triangle_cell_run(chunk.positions[t.x], chunk.positions[t.y], chunk.positions[t.z], frame, box_lower,
                                   box_upper, 0, grid.cells.z - 1,
                                   [&](std::uint32_t, std::uint32_t, std::uint32_t x_first, std::uint32_t x_last) {
                                     overlapped += x_last - x_first + 1;
                                   });
      }
      cells_spanned.fetch_add(overlapped, std::memory_order_relaxed);
      box_cells_spanned.fetch_add(box_overlapped, std::memory_order_relaxed);
    });
    if (any_chunks) {
      for (std::size_t i = (centroid_stride - first % centroid_stride) % centroid_stride; i < count; i += centroid_stride) {
        const glm::uvec3 t = chunk.triangles[i];
        centroids.push_back((chunk.positions[t.x] + chunk.positions[t.y] + chunk.positions[t.z]) / 3.0f);
      }
    }
    for (std::size_t p = 0; p < plans.size(); ++p) {
      const std::vector<ChunkRange>& chunks = plans[p];
      std::vector<Bounds3>& chunk_boxes = plan_boxes[p];
      for (std::size_t c = 0; c < chunks.size(); ++c) {
        const std::size_t begin = std::max(chunks[c].first, first);
        const std::size_t end = std::min(chunks[c].first + chunks[c].count, first + count);
        if (begin >= end) continue;
        chunk_boxes[c].extend(tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(begin - first, end - first), Bounds3{},
            [&](const tbb::blocked_range<std::size_t>& range, Bounds3 box) {
              for (std::size_t i = range.begin(); i != range.end(); ++i) {
                const glm::uvec3 t = chunk.triangles[i];
                for (const std::uint32_t corner : {t.x, t.y, t.z}) box.extend(chunk.positions[corner]);
              }
              return box;
            },
            [](Bounds3 a, const Bounds3& b) {
              a.extend(b);
              return a;
            }));
      }
    }
    if (!view) continue;
    nearest = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, count), nearest,
        [&](const tbb::blocked_range<std::size_t>& range, double least) {
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const glm::uvec3 t = chunk.triangles[i];
            const glm::vec3 &a = chunk.positions[t.x], &b = chunk.positions[t.y], &c = chunk.positions[t.z];
            if (!view->may_see(a, b, c)) continue;
            least = std::min(least, double(glm::distance(view->eye, closest_point_on_triangle(view->eye, a, b, c))));
          }
          return least;
        },
        [](double x, double y) { return std::min(x, y); });
  }
  traits.triangles_per_vertex = traits.vertices ? 3.0 * double(traits.triangles) / double(traits.vertices) : 0.0;
  traits.mesh_bytes_per_triangle = (12.0 * double(traits.vertices) + 16.0 * double(traits.triangles)) / double(traits.triangles);
  traits.grid_entries_per_triangle = cells.empty() ? 0.0 : double(cells_spanned.load()) / double(cells.size());
  traits.grid_box_entries_per_triangle = cells.empty() ? 0.0 : double(box_cells_spanned.load()) / double(cells.size());

  // Sum of n^2 over sum of n per occupied cell; with a sample of share f, n^2 - (1 - f) n
  // is f^2 times an unbiased estimate of the full cell's N^2, and n is f times N.
  tbb::parallel_sort(cells.begin(), cells.end());
  const double share = double(cells.size()) / double(traits.triangles);
  double squares = 0.0, total = 0.0;
  for (std::size_t run = 0; run < cells.size();) {
    std::size_t end = run;
    while (end < cells.size() && cells[end] == cells[run]) ++end;
    const double n = double(end - run);
    squares += n * n - (1.0 - share) * n;
    total += n;
    run = end;
  }
  traits.triangles_per_grid_cell = total > 0.0 ? std::max(1.0, squares / (share * total)) : 0.0;
  for (std::size_t p = 0; p < plans.size(); ++p) {
    SceneTraits::Chunking chunking{plan_sizes[p], 1.0, 1, {}};
    if (!plans[p].empty()) {
      chunking.chunks = plans[p].size();
      for (const ChunkRange& chunk : plans[p]) chunking.sizes.push_back(chunk.count);
      std::sort(chunking.sizes.begin(), chunking.sizes.end(), std::greater<>());
      // Samples times chunks box tests (a billion for a billion triangles in chunks of 64k): in parallel.
      const std::size_t containing = tbb::parallel_reduce(
          tbb::blocked_range<std::size_t>(0, centroids.size()), std::size_t{0},
          [&](const tbb::blocked_range<std::size_t>& range, std::size_t inside) {
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
              for (const Bounds3& box : plan_boxes[p]) {
                inside += glm::all(glm::lessThanEqual(box.lower, centroids[i])) &&
                          glm::all(glm::lessThanEqual(centroids[i], box.upper));
              }
            }
            return inside;
          },
          std::plus<>());
      chunking.overlap = centroids.empty() ? 1.0 : std::max(1.0, double(containing) / double(centroids.size()));
    }
    if (p == 0) {
      traits.chunks = plans[0].empty() ? 1 : chunking.chunks;
      traits.chunk_sizes = chunking.sizes;
      traits.chunk_overlap = chunking.overlap;
    } else if (!plans[p].empty()) {
      traits.smaller_chunkings.push_back(std::move(chunking));
    }
  }
  if (std::isfinite(nearest)) traits.nearest_in_view = nearest;
  return traits;
}

double half_pixel_footprint(const Camera& camera, const ImageSpec& image, double distance) {
  return distance * std::tan(0.5 * double(glm::radians(camera.vertical_fov_degrees))) / double(image.height);
}

AccelChoice choose_accelerator(const SceneTraits& traits, std::size_t budget_bytes, double max_error,
                               const AcceleratorOptions& base, bool streamed_source, const AutoAllowance& allowance) {
  AccelChoice choice;
  choice.budget_bytes = budget_bytes;
  choice.allowance = allowance;
  if (base.chunks_at_once != 0) choice.allowance.builds_at_once = std::min(allowance.builds_at_once, base.chunks_at_once);
  choice.max_error = max_error;
  choice.traits = traits;
  const double triangles = double(traits.triangles);
  AccelCandidate* fastest = nullptr;
  const std::vector<const AcceleratorType*> types = candidate_types();
  choice.candidates.reserve(types.size());
  for (const AcceleratorType* type : types) {
    const AutoCandidate& facts = type->automatic;
    AccelCandidate& candidate = choice.candidates.emplace_back(make_candidate(*type, base, max_error));
    // Chunks of the options' size first; a type built in chunks that fits in none of those
    // tries smaller ones, whose builds hold less at once and whose boxes overlap more.
    std::vector<SceneTraits::Chunking> chunkings = {
        {candidate.options.chunk_triangles, traits.chunk_overlap, traits.chunks, traits.chunk_sizes}};
    if (type->builds_in_chunks) chunkings.insert(chunkings.end(), traits.smaller_chunkings.begin(), traits.smaller_chunkings.end());
    bool one_at_a_time = false;
    const SceneTraits::Chunking* used = &chunkings.front();
    for (const SceneTraits::Chunking& chunking : chunkings) {
      used = &chunking;
      one_at_a_time = false;
      candidate.options.chunks_at_once = base.chunks_at_once;
      candidate.chunked = type->builds_in_chunks && traits.triangles > chunking.chunk_triangles;
      candidate.estimated_speed = facts.relative_speed / (candidate.chunked ? chunk_slowdown(chunking.overlap) : 1.0);
      // Peak while building: the structure, the whole mesh unless the type keeps its own
      // geometry and is built from a streamed source (counted apart even where the structure's
      // bytes include the mesh it reads in place: measured peaks need it), the temporaries of
      // the builds at once (the largest chunks, one per worker) and the process. On
      // builtin:room:8M (render, VmHWM), estimate against peak: robust Embree 1.19 / 1.02 GB,
      // bvh:width=8 1.57 / 1.54, hmq:width=8 0.90 / 0.64, raystrips:width=8 0.98 / 0.67;
      // `bench report` measures them on its scenes.
      double mesh = type->holds_own_geometry && streamed_source ? 0.0 : traits.mesh_bytes_per_triangle;
      // bvh's chunks keep copies of their meshes, beside a whole mesh that was not streamed.
      if (candidate.chunked && !type->holds_own_geometry && !streamed_source) mesh *= 2.0;
      const double grid_entries = candidate.options.mlgrid.bounding_box_lists ? traits.grid_box_entries_per_triangle
                                                                              : traits.grid_entries_per_triangle;
      double structure = facts.structure_from_grid_entries ? kGridBytesPerTriangle + kGridBytesPerEntry * grid_entries
                                                           : type->bytes_per_triangle(candidate.options);
      double build_temporaries = type->build_bytes_per_triangle;
      if (facts.grows_in_sparse_chunks && candidate.chunked) {
        const double sparse = std::max(1.0, kConnectedTrianglesPerVertex / std::max(traits.triangles_per_vertex, 1.0));
        structure *= sparse;
        build_temporaries *= sparse;
      }
      // The peak with `at_once` chunks built at the same time (the largest ones).
      const auto estimate = [&](std::size_t at_once) {
        double built_at_once = triangles;
        if (candidate.chunked) {
          built_at_once = 0.0;
          for (std::size_t c = 0; c < std::min(chunking.sizes.size(), at_once); ++c) {
            built_at_once += double(chunking.sizes[c]);
          }
          if (chunking.sizes.empty()) built_at_once = std::min(triangles, double(chunking.chunk_triangles));
        }
        return triangles * (structure + mesh) + built_at_once * build_temporaries + double(allowance.process_bytes);
      };
      candidate.estimated_bytes = estimate(choice.allowance.builds_at_once);
      candidate.fits = candidate.estimated_bytes <= double(budget_bytes);
      // A chunked build that fits one chunk at a time is built so (build.chunks_at_once = 1):
      // its cores share each chunk, a quarter slower to build at room:64M, no slower to trace.
      if (!candidate.fits && candidate.chunked && choice.allowance.builds_at_once > 1 &&
          estimate(1) <= double(budget_bytes)) {
        candidate.estimated_bytes = estimate(1);
        candidate.fits = true;
        candidate.options.chunks_at_once = 1;
        one_at_a_time = true;
      }
      if (candidate.fits) break;
    }
    if (used != &chunkings.front()) {
      candidate.options.chunk_triangles = used->chunk_triangles;
      candidate.spec += fmt::format(":chunk_triangles={}", used->chunk_triangles);
    }
    if (one_at_a_time) candidate.spec += ":chunks_at_once=1";

    std::string error_reason;
    candidate.meets_error = true;
    if (facts.lossy) {
      if (!(max_error > 0.0)) {
        candidate.meets_error = false;
        error_reason = "accel.max_error = 0 asks for an exact method";
      } else {
        try {
          const GlobalGrid grid = grid_from_epsilon(traits.bounds, max_error);
          error_reason = fmt::format("grid {}x{}x{} bits keeps vertices within {:.3g}", grid.bits.x, grid.bits.y,
                                     grid.bits.z, grid.max_vertex_error);
        } catch (const std::invalid_argument& error) {
          candidate.meets_error = false;  // huge extents or thin features: the grid cannot be that fine
          error_reason = error.what();
        }
      }
    }
    if (facts.failure == KnownFailure::triangle_soup && traits.triangles_per_vertex < kSoupTrianglesPerVertex) {
      candidate.failure_case = fmt::format("a soup ({:.2f} triangles per vertex): strips of one triangle each",
                                           traits.triangles_per_vertex);
    }
    if (facts.failure == KnownFailure::crowded_cells && traits.triangles_per_grid_cell > kCrowdedGridCell) {
      candidate.failure_case = fmt::format("crowded cells: {:.0f} triangles share an average triangle's grid cell",
                                           traits.triangles_per_grid_cell);
    }

    const std::string size = fmt::format("about {} of {}", gigabytes(candidate.estimated_bytes), gigabytes(double(budget_bytes)));
    const std::string speed =
        candidate.chunked ? fmt::format("{:.2f}x robust Embree's speed ({} chunks{}, {:.2f} boxes around a triangle)",
                                        candidate.estimated_speed, used->chunks,
                                        one_at_a_time ? " built one at a time" : "", used->overlap)
                          : fmt::format("{:.2f}x robust Embree's speed", candidate.estimated_speed);
    if (!candidate.fits) {
      candidate.reason = "needs " + size;
    } else if (!candidate.meets_error) {
      candidate.reason = fmt::format("error bound {:.3g}: {}", max_error, error_reason);
    } else if (candidate.failure_case) {
      candidate.reason = "its failure case: " + *candidate.failure_case;
    } else {
      candidate.reason = fmt::format("fits ({}), {}, {}", size, speed, facts.lossy ? error_reason : std::string("exact"));
      if (fastest == nullptr || candidate.estimated_speed > fastest->estimated_speed) fastest = &candidate;
    }
  }
  if (fastest != nullptr) {
    fastest->chosen = true;
    choice.options = fastest->options;
    choice.spec = fastest->spec;
    for (AccelCandidate& candidate : choice.candidates) {
      if (!candidate.chosen && candidate.reason.starts_with("fits")) {
        candidate.reason = fmt::format("slower than {} ({:.2f}x against {:.2f}x)", fastest->spec,
                                       candidate.estimated_speed, fastest->estimated_speed);
      }
    }
  }
  std::string passed;
  for (const AccelCandidate& candidate : choice.candidates) {
    if (!candidate.chosen) passed += fmt::format("; {}: {}", candidate.spec, candidate.reason);
  }
  if (choice.spec.empty()) {
    throw ConfigError(fmt::format("accel.type = auto: no accelerator fits accel.memory_budget and accel.max_error{}",
                                  passed));
  }
  const auto chosen = std::find_if(choice.candidates.begin(), choice.candidates.end(),
                                   [](const AccelCandidate& c) { return c.chosen; });
  choice.summary = fmt::format("accel auto: {} ({}){}", choice.spec, chosen->reason, passed);
  return choice;
}

nlohmann::json to_json(const AccelChoice& choice) {
  nlohmann::json candidates = nlohmann::json::array();
  for (const AccelCandidate& c : choice.candidates) {
    candidates.push_back({{"spec", c.spec},
                          {"estimated_speed", c.estimated_speed},
                          {"chunked", c.chunked},
                          {"estimated_bytes", c.estimated_bytes},
                          {"fits", c.fits},
                          {"meets_error", c.meets_error},
                          {"failure_case", c.failure_case ? nlohmann::json(*c.failure_case) : nlohmann::json(nullptr)},
                          {"chosen", c.chosen},
                          {"reason", c.reason}});
  }
  const SceneTraits& t = choice.traits;
  return {{"chosen", choice.spec},
          {"budget_bytes", choice.budget_bytes},
          {"process_bytes", choice.allowance.process_bytes},
          {"builds_at_once", choice.allowance.builds_at_once},
          {"mesh_bytes_per_triangle", choice.traits.mesh_bytes_per_triangle},
          {"max_error", choice.max_error},
          {"pixel_distance", choice.pixel_distance ? nlohmann::json(*choice.pixel_distance) : nlohmann::json(nullptr)},
          {"traits",
           {{"triangles", t.triangles},
            {"vertices", t.vertices},
            {"triangles_per_vertex", t.triangles_per_vertex},
            {"triangles_per_grid_cell", t.triangles_per_grid_cell},
            {"grid_entries_per_triangle", t.grid_entries_per_triangle},
            {"grid_box_entries_per_triangle", t.grid_box_entries_per_triangle},
            {"mesh_bytes_per_triangle", t.mesh_bytes_per_triangle},
            {"chunks", t.chunks},
            {"chunk_overlap", t.chunk_overlap},
            {"nearest_in_view", t.nearest_in_view ? nlohmann::json(*t.nearest_in_view) : nlohmann::json(nullptr)}}},
          {"candidates", candidates}};
}

std::string resolution_summary(const ResolvedAccelerator& resolved) {
  if (resolved.choice) return resolved.choice->summary;
  if (!resolved.pixel_epsilon) return {};
  return fmt::format("accel hmq: epsilon = pixel = {:.4g} (half a pixel's footprint at {:.4g}, the nearest surface in view)",
                     *resolved.pixel_epsilon, *resolved.pixel_distance);
}

bool pixel_epsilon_applies(const AcceleratorOptions& options, const AccelGoal& goal) {
  // accel.hmq.epsilon = pixel bounds the type whose error it sets: the lossy one.
  const AcceleratorType* type = find_accelerator_type(options.type);
  return goal.hmq_epsilon_pixel && type != nullptr && type->automatic.lossy;
}

ResolvedAccelerator resolve_accelerator(const AcceleratorOptions& options, const AccelGoal& goal,
                                        const TriangleSource& source, const Camera& camera, const ImageSpec& image,
                                        bool streamed_source) {
  ResolvedAccelerator resolved{options, std::nullopt, std::nullopt, std::nullopt};
  const bool hmq_pixel = pixel_epsilon_applies(options, goal);
  if (!goal.automatic && !hmq_pixel) return resolved;
  const bool needs_pixel = hmq_pixel || (goal.automatic && !goal.max_error);
  const SceneTraits traits = measure_scene_traits(source, goal.automatic ? options.chunk_triangles : 0,
                                                  needs_pixel ? &camera : nullptr, &image, goal.automatic);
  if (needs_pixel) {
    if (!traits.nearest_in_view) {
      throw ConfigError("an error bound of 'pixel' needs a surface in view, and no triangle lies in the camera's view");
    }
    const double epsilon = half_pixel_footprint(camera, image, *traits.nearest_in_view);
    if (!(epsilon > 0.0)) {
      throw ConfigError(fmt::format("an error bound of 'pixel' is 0: the camera lies on a surface (nearest in view "
                                    "{:g}); give accel.max_error or accel.hmq.epsilon in scene units",
                                    *traits.nearest_in_view));
    }
    resolved.pixel_epsilon = epsilon;
    resolved.pixel_distance = traits.nearest_in_view;
  }
  if (hmq_pixel && !goal.automatic) {
    resolved.options.hmq.epsilon = *resolved.pixel_epsilon;
    return resolved;
  }
  AccelChoice choice = choose_accelerator(traits, resolve_accel_memory_budget(goal.memory_budget),
                                          goal.max_error.value_or(resolved.pixel_epsilon.value_or(0.0)), options,
                                          streamed_source, auto_allowance(image));
  if (needs_pixel) choice.pixel_distance = traits.nearest_in_view;
  resolved.options = choice.options;
  resolved.choice = std::move(choice);
  return resolved;
}

}  // namespace wavetrace
