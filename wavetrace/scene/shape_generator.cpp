// Extraction of a range of a generated shape: corner keys, their sorted unique set as the
// range's vertices, and the corners renumbered into it.
#include "wavetrace/scene/shape_generator.hpp"

#include <algorithm>
#include <atomic>
#include <limits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include "wavetrace/memory/cache_aligned_allocator.hpp"

namespace wavetrace {
namespace {

// Triangles a task generates at once: large enough to amortize finding its start.
constexpr std::size_t kTrianglesPerTask = std::size_t{1} << 16;

template <typename Body>
void for_each_block(std::size_t first, std::size_t count, Body&& body) {
  const std::size_t blocks = (count + kTrianglesPerTask - 1) / kTrianglesPerTask;
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t block) {
    const std::size_t begin = first + block * kTrianglesPerTask;
    body(begin, std::min(kTrianglesPerTask, first + count - begin));
  });
}

void fill_materials(const ShapeGenerator& shape, std::size_t first, TriangleMesh& mesh) {
  if (shape.material_count() <= 1) return;
  mesh.material_of_triangle.resize(mesh.triangles.size());
  tbb::parallel_for(std::size_t{0}, mesh.triangles.size(),
                    [&](std::size_t t) { mesh.material_of_triangle[t] = shape.material(first + t); });
}

// A dense shape's range: its keys lie in [0, vertex_count) in a few clusters (a chunk of an
// icosphere uses a stretch of one face's interior and some of the edge vertices, which are
// numbered before every face's). Each block of 2^16 keys that holds any of them gets a slice
// of a table that marks the used keys and numbers them in key order by a prefix sum, as
// sorting the keys, dropping repeats and searching each corner did (a third of a room's
// chunked build, and most of a billion-triangle room's extraction while one table had to span
// the edge vertices and the face together). Only where the slices hold at most
// kDenseSpanPerKey entries a key (16 bytes a key), or 2^20 in all; false, and nothing done,
// where they would not.
constexpr std::size_t kDenseSpanPerKey = 4;
constexpr int kKeyBlockBits = 16;
constexpr std::uint64_t kKeyBlockMask = (std::uint64_t{1} << kKeyBlockBits) - 1;

bool renumber_dense_keys(const ShapeGenerator& shape, const UnfilledLargeArray<std::uint64_t>& keys, const glm::vec3& offset,
                         TriangleMesh& mesh) {
  // Not a structured binding: lambdas below capture the two, which clang 14 refuses.
  const std::pair<std::uint64_t, std::uint64_t> key_span = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, keys.size(), 1 << 14),
      std::pair(std::numeric_limits<std::uint64_t>::max(), std::uint64_t{0}),
      [&](const tbb::blocked_range<std::size_t>& range, std::pair<std::uint64_t, std::uint64_t> span) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
          span.first = std::min(span.first, keys[k]);
          span.second = std::max(span.second, keys[k]);
        }
        return span;
      },
      [](auto a, const auto& b) { return std::pair(std::min(a.first, b.first), std::max(a.second, b.second)); });
  const std::uint64_t lowest = key_span.first, highest = key_span.second;
  const std::size_t blocks = ((highest - lowest) >> kKeyBlockBits) + 1;
  if (blocks > keys.size()) return false;
  // Marked blocks, then each used block's slice, plus one.
  std::vector<std::uint32_t> slice_of_block(blocks, 0);
  tbb::parallel_for(std::size_t{0}, keys.size(), [&](std::size_t k) {
    std::atomic_ref<std::uint32_t>(slice_of_block[(keys[k] - lowest) >> kKeyBlockBits]).store(1, std::memory_order_relaxed);
  });
  std::vector<std::uint64_t> block_first_key;  // by slice
  for (std::size_t block = 0; block < blocks; ++block) {
    if (slice_of_block[block] == 0) continue;
    block_first_key.push_back(lowest + (std::uint64_t(block) << kKeyBlockBits));
    slice_of_block[block] = static_cast<std::uint32_t>(block_first_key.size());
  }
  const std::size_t entries = block_first_key.size() << kKeyBlockBits;
  if (entries > std::max(kDenseSpanPerKey * keys.size(), std::size_t{1} << 20)) return false;
  LargeArray<std::uint32_t> number(entries, 0);
  const auto entry = [&](std::uint64_t key) -> std::uint32_t& {
    const std::uint64_t from_lowest = key - lowest;
    const std::size_t slice = slice_of_block[from_lowest >> kKeyBlockBits] - 1;
    return number[(slice << kKeyBlockBits) | (from_lowest & kKeyBlockMask)];
  };
  tbb::parallel_for(std::size_t{0}, keys.size(), [&](std::size_t k) {
    std::atomic_ref<std::uint32_t>(entry(keys[k])).store(1, std::memory_order_relaxed);
  });
  std::uint32_t used = 0;
  for (std::uint32_t& slot : number) {  // marked slots become their vertex's number, plus one
    if (slot != 0) slot = ++used;
  }
  mesh.positions.reserve(used + 1);  // the read slack TriangleMesh users expect, without a copy
  mesh.positions.resize(used);
  tbb::parallel_for(std::size_t{0}, entries, [&](std::size_t e) {
    if (number[e] == 0) return;
    const std::uint64_t key = block_first_key[e >> kKeyBlockBits] + (e & kKeyBlockMask);
    mesh.positions[number[e] - 1] = shape.position(key) + offset;
  });
  tbb::parallel_for(std::size_t{0}, mesh.triangles.size(), [&](std::size_t t) {
    mesh.triangles[t] = glm::uvec3(entry(keys[3 * t]) - 1, entry(keys[3 * t + 1]) - 1, entry(keys[3 * t + 2]) - 1);
  });
  return true;
}

}  // namespace

TriangleMesh generate_range(const ShapeGenerator& shape, std::size_t first, std::size_t count, const glm::vec3& offset) {
  if (first > shape.triangle_count() || count > shape.triangle_count() - first) {
    throw std::out_of_range(fmt::format("shape range [{}, {}) beyond its {} triangles", first, first + count,
                                        shape.triangle_count()));
  }
  TriangleMesh mesh;
  mesh.triangles.resize(count);
  const bool whole_dense = shape.vertex_count() > 0 && first == 0 && count == shape.triangle_count();
  if (whole_dense) {
    if (shape.vertex_count() > std::numeric_limits<std::uint32_t>::max()) {
      throw SceneError(fmt::format("a shape of {} vertices is beyond 32-bit indices", shape.vertex_count()));
    }
    mesh.positions.reserve(shape.vertex_count() + 1);
    mesh.positions.resize(shape.vertex_count());
    tbb::parallel_for(std::size_t{0}, mesh.positions.size(),
                      [&](std::size_t v) { mesh.positions[v] = shape.position(v) + offset; });
    for_each_block(first, count, [&](std::size_t begin, std::size_t size) {
      std::vector<std::uint64_t> keys(3 * size);
      shape.corners(begin, size, keys.data());
      for (std::size_t t = 0; t < size; ++t) {
        mesh.triangles[begin - first + t] = glm::uvec3(keys[3 * t], keys[3 * t + 1], keys[3 * t + 2]);
      }
    });
    fill_materials(shape, first, mesh);
    return mesh;
  }
  UnfilledLargeArray<std::uint64_t> keys(3 * count);  // every key written by the blocks, in parallel
  for_each_block(first, count, [&](std::size_t begin, std::size_t size) { shape.corners(begin, size, keys.data() + 3 * (begin - first)); });
  if (shape.vertex_count() > 0 && renumber_dense_keys(shape, keys, offset, mesh)) {
    fill_materials(shape, first, mesh);
    return mesh;
  }
  LargeArray<std::uint64_t> vertices(keys.size());
  std::copy(keys.begin(), keys.end(), vertices.begin());
  tbb::parallel_sort(vertices.begin(), vertices.end());
  const std::size_t unique = std::unique(vertices.begin(), vertices.end()) - vertices.begin();
  if (unique > std::numeric_limits<std::uint32_t>::max()) {
    throw SceneError(fmt::format("a chunk of {} vertices is beyond 32-bit indices", unique));
  }
  mesh.positions.reserve(unique + 1);
  mesh.positions.resize(unique);
  tbb::parallel_for(std::size_t{0}, unique, [&](std::size_t v) { mesh.positions[v] = shape.position(vertices[v]) + offset; });
  const std::uint64_t* sorted = vertices.data();
  tbb::parallel_for(std::size_t{0}, count, [&](std::size_t t) {
    std::uint32_t local[3];
    for (int k = 0; k < 3; ++k) {
      local[k] = static_cast<std::uint32_t>(std::lower_bound(sorted, sorted + unique, keys[3 * t + k]) - sorted);
    }
    mesh.triangles[t] = glm::uvec3(local[0], local[1], local[2]);
  });
  fill_materials(shape, first, mesh);
  return mesh;
}

Bounds3 generated_bounds(const ShapeGenerator& shape, const glm::vec3& offset, const Bounds3* known) {
  const bool dense = shape.vertex_count() > 0;
  const std::size_t items = dense ? shape.vertex_count() : shape.triangle_count();
  // Strictly inside by a margin, so that a vertex left out can equal no side of `known` (not
  // even as a zero of the other sign) and rounding in a bound cannot matter.
  Bounds3 inner;
  if (known != nullptr && !known->empty()) {
    const glm::vec3 margin(1e-4f * glm::length(known->extent()) + 1e-30f);
    inner = Bounds3{known->lower + margin, known->upper - margin};
  }
  const auto add = [&](std::uint64_t key, Bounds3& box) {
    if (!inner.empty()) {
      if (const std::optional<Bounds3> bound = shape.position_bound(key)) {
        const glm::vec3 lower = bound->lower + offset, upper = bound->upper + offset;
        if (glm::all(glm::greaterThan(lower, inner.lower)) && glm::all(glm::lessThan(upper, inner.upper))) return;
      }
    }
    box.extend(shape.position(key) + offset);
  };
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, items, 4096), Bounds3{},
      [&](const tbb::blocked_range<std::size_t>& range, Bounds3 box) {
        if (dense) {
          for (std::size_t v = range.begin(); v != range.end(); ++v) add(v, box);
          return box;
        }
        std::vector<std::uint64_t> keys(3 * range.size());
        shape.corners(range.begin(), range.size(), keys.data());
        for (const std::uint64_t key : keys) add(key, box);
        return box;
      },
      [](Bounds3 a, const Bounds3& b) {
        a.extend(b);
        return a;
      });
}

TriangleMesh generate_mesh(const ShapeGenerator& shape, const glm::vec3& offset) {
  return generate_range(shape, 0, shape.triangle_count(), offset);
}

}  // namespace wavetrace
