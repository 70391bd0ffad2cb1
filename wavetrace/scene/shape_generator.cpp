// Extraction of a range of a generated shape: corner keys, their sorted unique set as the
// range's vertices, and the corners renumbered into it.
#include "wavetrace/scene/shape_generator.hpp"

#include <algorithm>
#include <atomic>
#include <limits>
#include <utility>
#include <vector>

#include <fmt/format.h>
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

// A dense shape's range: its keys lie in [0, vertex_count), so a table over the keys' span
// marks the used ones and numbers them in key order by a prefix sum, as sorting the keys,
// dropping repeats and searching each corner did (a third of a room's chunked build). Only
// where the span is at most kDenseSpanPerKey times the keys (a table of 16 bytes a key or
// less); false, and nothing done, where it is not (a chunk of a shape far larger than it:
// an icosphere's corner and edge vertices are numbered before every face's).
constexpr std::size_t kDenseSpanPerKey = 4;

bool renumber_dense_keys(const ShapeGenerator& shape, const LargeArray<std::uint64_t>& keys, const glm::vec3& offset,
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
  const std::size_t span = highest - lowest + 1;  // at most the shape's vertex count
  if (span > kDenseSpanPerKey * keys.size()) return false;
  LargeArray<std::uint32_t> number(span, 0);
  tbb::parallel_for(std::size_t{0}, keys.size(), [&](std::size_t k) {
    std::atomic_ref<std::uint32_t>(number[keys[k] - lowest]).store(1, std::memory_order_relaxed);
  });
  std::uint32_t used = 0;
  for (std::uint32_t& slot : number) {  // marked slots become their vertex's number, plus one
    if (slot != 0) slot = ++used;
  }
  mesh.positions.resize(used);
  tbb::parallel_for(std::size_t{0}, span, [&](std::size_t k) {
    if (number[k] != 0) mesh.positions[number[k] - 1] = shape.position(lowest + k) + offset;
  });
  tbb::parallel_for(std::size_t{0}, mesh.triangles.size(), [&](std::size_t t) {
    mesh.triangles[t] = glm::uvec3(number[keys[3 * t] - lowest] - 1, number[keys[3 * t + 1] - lowest] - 1,
                                   number[keys[3 * t + 2] - lowest] - 1);
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
  LargeArray<std::uint64_t> keys(3 * count);
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

Bounds3 generated_bounds(const ShapeGenerator& shape, const glm::vec3& offset) {
  const bool dense = shape.vertex_count() > 0;
  const std::size_t items = dense ? shape.vertex_count() : shape.triangle_count();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, items, 4096), Bounds3{},
      [&](const tbb::blocked_range<std::size_t>& range, Bounds3 box) {
        if (dense) {
          for (std::size_t v = range.begin(); v != range.end(); ++v) box.extend(shape.position(v) + offset);
          return box;
        }
        std::vector<std::uint64_t> keys(3 * range.size());
        shape.corners(range.begin(), range.size(), keys.data());
        for (const std::uint64_t key : keys) box.extend(shape.position(key) + offset);
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
