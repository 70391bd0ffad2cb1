// Leaf encoding: strips inside the leaf (greedy, no swaps: the table has no room for
// them), the strip-or-indexed choice, and the min-max offsets of every vertex.
#include "wavetrace/accel/hmq/leaf_codec.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <stdexcept>

#include <immintrin.h>

namespace wavetrace::hmq {
namespace {

std::uint32_t bits_for(std::uint32_t largest) { return largest == 0 ? 0 : std::bit_width(largest); }

// A leaf's short lists, on the stack: a leaf has at most 14 triangles and 42 strip slots, and
// with vectors the encoder made a dozen heap allocations a leaf (an eighth of an hmq build).
template <typename T, std::size_t kCapacity>
class LeafList {
 public:
  void push_back(T value) { items_[size_++] = value; }
  void clear() { size_ = 0; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  T& operator[](std::size_t i) { return items_[i]; }
  const T& operator[](std::size_t i) const { return items_[i]; }
  T* begin() { return items_.data(); }
  T* end() { return items_.data() + size_; }
  const T* begin() const { return items_.data(); }
  const T* end() const { return items_.data() + size_; }
  const T* data() const { return items_.data(); }
  operator std::span<const T>() const { return {items_.data(), size_}; }

 private:
  std::array<T, kCapacity> items_;
  std::size_t size_ = 0;
};

constexpr std::size_t kMaxLeafSlots = 3 * kMaxLeafTriangles;  // a strip of n triangles has n + 2 slots
using TriangleList = LeafList<std::uint32_t, kMaxLeafTriangles>;
using SlotList = LeafList<std::uint32_t, kMaxLeafSlots>;

// The leaf's strips, longest first (ties in the order they were made), laid end to end.
struct LeafStrips {
  TriangleList lengths;   // triangles of each strip
  SlotList slot_vertex;   // mesh vertex ids, length + 2 a strip
  TriangleList triangles; // mesh triangle ids, strip after strip
};

// Greedy strips without swaps over at most 14 triangles: start at the triangle with the
// fewest unused neighbours, leave it through its most constrained neighbour, go straight.
// Neighbours are masks over the leaf's triangles, each edge's found once a leaf (asking the
// mesh again for every candidate was a quarter of an hmq build); the lowest unused
// neighbour is taken, as the scan over the leaf's triangles took it.
LeafStrips strips_of_leaf(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles) {
  const std::size_t count = triangles.size();
  std::array<glm::uvec3, kMaxLeafTriangles> corners;
  for (std::size_t i = 0; i < count; ++i) corners[i] = mesh.triangles[triangles[i]];
  // The corners again by position, a lane a triangle (16 lanes, those past the leaf masked off),
  // so that an edge is compared with every triangle at once: the edge tests were a third of
  // the encoding, one corner at a time.
  alignas(32) std::uint32_t corner_lanes[3][16] = {};
  for (std::size_t i = 0; i < count; ++i) {
    for (int k = 0; k < 3; ++k) corner_lanes[k][i] = corners[i][k];
  }
  static_assert(kMaxLeafTriangles <= 16);
  const std::uint32_t leaf_lanes = (1u << count) - 1u;
  // The leaf's triangles sharing the edge (a, b): two of their corners are a or b.
  const auto across = [&](std::uint32_t a, std::uint32_t b) {
    if (a == b) return 0u;
    const __m256i edge_a = _mm256_set1_epi32(int(a)), edge_b = _mm256_set1_epi32(int(b));
    std::uint32_t mask = 0;
    for (int half = 0; half < 2; ++half) {
      __m256i found = _mm256_setzero_si256();  // corners equal to a or b (a != b: one test at most is true)
      for (int k = 0; k < 3; ++k) {
        const __m256i corner = _mm256_load_si256(reinterpret_cast<const __m256i*>(corner_lanes[k] + 8 * half));
        found = _mm256_sub_epi32(found, _mm256_cmpeq_epi32(corner, edge_a));
        found = _mm256_sub_epi32(found, _mm256_cmpeq_epi32(corner, edge_b));
      }
      const __m256i two = _mm256_cmpeq_epi32(found, _mm256_set1_epi32(2));
      mask |= std::uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(two))) << (8 * half);
    }
    return mask & leaf_lanes;
  };
  std::array<std::array<std::uint32_t, 3>, kMaxLeafTriangles> edge_neighbours;  // triangle i itself left out
  for (std::size_t i = 0; i < count; ++i) {
    for (int e = 0; e < 3; ++e) edge_neighbours[i][e] = across(corners[i][e], corners[i][(e + 1) % 3]) & ~(1u << i);
  }
  std::uint32_t used = 0;
  const auto lowest = [&](std::uint32_t mask) { return mask == 0 ? count : std::size_t(std::countr_zero(mask)); };
  const auto unused_degree = [&](std::size_t i) {
    int degree = 0;
    for (int e = 0; e < 3; ++e) degree += (edge_neighbours[i][e] & ~used) != 0;
    return degree;
  };
  LeafStrips made;  // in the order made
  TriangleList first_slot, first_triangle;
  for (std::size_t remaining = count; remaining > 0;) {
    // The first unused triangle of the fewest unused neighbours (none has more than three).
    std::size_t start = count;
    for (std::uint32_t unused = leaf_lanes & ~used, least = 4; unused != 0 && least > 0; unused &= unused - 1) {
      const std::size_t i = std::size_t(std::countr_zero(unused));
      const std::uint32_t degree = std::uint32_t(unused_degree(i));
      if (degree < least) start = i, least = degree;
    }
    used |= 1u << start;
    --remaining;
    const glm::uvec3& c = corners[start];
    int edge = -1;
    std::size_t best = count;
    for (int e = 0; e < 3; ++e) {
      const std::size_t next = lowest(edge_neighbours[start][e] & ~used);
      if (next != count && (best == count || unused_degree(next) < unused_degree(best))) best = next, edge = e;
    }
    if (edge < 0) edge = 0;
    first_slot.push_back(static_cast<std::uint32_t>(made.slot_vertex.size()));
    first_triangle.push_back(static_cast<std::uint32_t>(made.triangles.size()));
    SlotList& slots = made.slot_vertex;
    slots.push_back(c[(edge + 2) % 3]);
    slots.push_back(c[edge]);
    slots.push_back(c[(edge + 1) % 3]);
    made.triangles.push_back(triangles[start]);
    std::uint32_t length = 1;
    while (remaining > 0) {
      const std::size_t size = slots.size();
      const std::size_t next = lowest(across(slots[size - 2], slots[size - 1]) & ~used);
      if (next == count) break;
      used |= 1u << next;
      --remaining;
      const glm::uvec3& n = corners[next];
      for (int k = 0; k < 3; ++k) {
        if (n[k] != slots[size - 2] && n[k] != slots[size - 1]) {
          slots.push_back(n[k]);
          break;
        }
      }
      made.triangles.push_back(triangles[next]);
      ++length;
    }
    made.lengths.push_back(length);
  }
  // Longest first, stably (an insertion sort: at most 14 strips).
  TriangleList order;
  for (std::uint32_t strip = 0; strip < made.lengths.size(); ++strip) {
    std::size_t at = order.size();
    order.push_back(strip);
    for (; at > 0 && made.lengths[order[at - 1]] < made.lengths[strip]; --at) order[at] = order[at - 1];
    order[at] = strip;
  }
  LeafStrips strips;
  for (const std::uint32_t strip : order) {
    const std::uint32_t length = made.lengths[strip];
    strips.lengths.push_back(length);
    for (std::uint32_t k = 0; k < length + 2; ++k) strips.slot_vertex.push_back(made.slot_vertex[first_slot[strip] + k]);
    for (std::uint32_t k = 0; k < length; ++k) strips.triangles.push_back(made.triangles[first_triangle[strip] + k]);
  }
  return strips;
}

}  // namespace

std::size_t encode_leaf(const QuantizedMesh& quantized, std::span<const std::uint32_t> triangles, const GridBox& box,
                        LargeArray<std::byte>& out) {
  if (triangles.empty() || triangles.size() > kMaxLeafTriangles) {
    throw std::invalid_argument("hmq: a leaf holds 1 .. 14 triangles");
  }
  const TriangleMesh& mesh = *quantized.mesh;
  const LeafStrips strips = strips_of_leaf(mesh, triangles);
  const SlotList& slot_vertex = strips.slot_vertex;
  const TriangleList& leaf_triangles = strips.triangles;
  const StripTable& table = StripTable::instance();
  const std::uint32_t entry = table.find(strips.lengths);
  const StripLayoutEntry& layout = table.entry(entry);

  // Unique vertices in first-use order, for the indexed form.
  SlotList unique, slot_index;
  for (const std::uint32_t vertex : slot_vertex) {
    const auto found = std::find(unique.begin(), unique.end(), vertex);
    slot_index.push_back(static_cast<std::uint32_t>(found - unique.begin()));
    if (found == unique.end()) unique.push_back(vertex);
  }
  // Offsets from the nearer plane of the leaf's grid box, per axis (the min-max trick).
  auto offsets = [&](const SlotList& vertices, int axis, std::uint32_t& bits, SlotList& values) {
    values.clear();
    std::uint32_t largest = 0;
    for (const std::uint32_t vertex : vertices) {
      const int line = quantized.lines[vertex][axis];
      const int from_lower = line - box.lower[axis], from_upper = box.upper[axis] - line;
      if (from_lower < 0 || from_upper < 0) throw std::logic_error("hmq: a vertex outside its leaf's grid box");
      const bool upper = from_upper < from_lower;
      const auto offset = static_cast<std::uint32_t>(upper ? from_upper : from_lower);
      largest = std::max(largest, offset);
      values.push_back(offset << 1 | (upper ? 1u : 0u));
    }
    bits = bits_for(largest);
  };
  const std::uint32_t index_bits = bits_for(static_cast<std::uint32_t>(unique.size() - 1));
  std::uint32_t axis_bits[3];
  SlotList streams[3];
  for (int axis = 0; axis < 3; ++axis) offsets(unique, axis, axis_bits[axis], streams[axis]);
  std::size_t indexed_bits = stream_bits(index_bits, layout.slots), strip_bits = 0;
  for (int axis = 0; axis < 3; ++axis) {
    indexed_bits += stream_bits(axis_bits[axis] + 1, static_cast<std::uint32_t>(unique.size()));
    strip_bits += stream_bits(axis_bits[axis] + 1, layout.slots);
  }
  const bool indexed = indexed_bits < strip_bits;
  if (!indexed) {
    for (int axis = 0; axis < 3; ++axis) offsets(slot_vertex, axis, axis_bits[axis], streams[axis]);
  }
  const std::uint32_t vertex_count = indexed ? static_cast<std::uint32_t>(unique.size()) : layout.slots;

  std::uint32_t id_base = *std::min_element(leaf_triangles.begin(), leaf_triangles.end());
  TriangleList id_delta, corners;
  std::uint32_t largest_delta = 0;
  for (std::uint32_t k = 0; k < leaf_triangles.size(); ++k) {
    const std::uint32_t triangle = leaf_triangles[k];
    id_delta.push_back(triangle - id_base);
    largest_delta = std::max(largest_delta, triangle - id_base);
    const std::uint32_t* slot = slot_vertex.data() + layout.first_slot[k];
    auto corner_of = [&](std::uint32_t vertex) {
      for (std::uint32_t c = 0; c < 3; ++c) {
        if (slot[c] == vertex) return c;
      }
      throw std::logic_error("hmq: a leaf triangle does not have its mesh triangle's corners");
    };
    const glm::uvec3& c = mesh.triangles[triangle];
    corners.push_back(3 * corner_of(c.y) + corner_of(c.z));
  }
  const std::uint32_t id_bits = bits_for(largest_delta);
  if (id_bits > 31) throw std::length_error("hmq: a leaf's triangle ids span 2^31 or more");
  const std::uint32_t base_bits = std::max(1u, bits_for(id_base));

  BitWriter record(out);
  record.append(entry | std::uint32_t(indexed) << 9 | vertex_count << 10, 16);
  for (int axis = 0; axis < 3; ++axis) record.append(axis_bits[axis], 5);
  record.append(id_bits, 5);
  record.append(base_bits - 1, 5);
  record.append(id_base, base_bits);
  for (int axis = 0; axis < 3; ++axis) record.append_stream(streams[axis], axis_bits[axis] + 1);
  if (indexed) record.append_stream(slot_index, index_bits);
  record.append_stream(id_delta, id_bits);
  record.append_stream(corners, 3);
  record.finish();
  return base_bits + stream_bits(id_bits + 3, static_cast<std::uint32_t>(leaf_triangles.size()));
}

std::size_t leaf_record_bytes(const std::byte* record) {
  const LeafHeader header = read_leaf_header(record);
  return leaf_record_bytes(header, StripTable::instance().entry(header.entry));
}

}  // namespace wavetrace::hmq
