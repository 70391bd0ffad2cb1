// The BVH baseline: builder invariants, agreement with Embree on the same rays, any-hit
// against closest-hit, identical hits for every layout, and no leaks.
#include <algorithm>
#include <functional>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <glm/vector_relational.hpp>

#include "wavetrace/accel/bvh/bvh_accelerator.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/bench/leak_bench.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "accel_agreement.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

std::vector<Bounds3> triangle_bounds(const TriangleMesh& mesh) {
  std::vector<Bounds3> bounds(mesh.triangle_count());
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) bounds[t].extend(mesh.positions[mesh.triangles[t][k]]);
  }
  return bounds;
}

bool contains(const Bounds3& outer, const Bounds3& inner) {
  return glm::all(glm::lessThanEqual(outer.lower, inner.lower)) && glm::all(glm::greaterThanEqual(outer.upper, inner.upper));
}

TEST(SahBuilder, EveryPrimitiveOnceLeavesSmallBoundsNested) {
  const Scene scene = make_builtin_scene("builtin:sphere:20k");
  const std::vector<Bounds3> bounds = triangle_bounds(scene.mesh);
  for (std::uint32_t leaf_size : {1u, 4u, 16u}) {
    SahOptions options;
    options.max_leaf_size = leaf_size;
    const BuildTree tree = build_sah_tree(bounds, options);
    std::vector<int> seen(bounds.size(), 0);
    std::size_t leaves = 0;
    for (const BuildNode& node : tree.nodes) {
      if (node.leaf()) {
        ++leaves;
        EXPECT_LE(node.count, leaf_size);
        for (std::uint32_t k = 0; k < node.count; ++k) {
          const std::uint32_t primitive = tree.primitive_order[node.first + k];
          ++seen[primitive];
          EXPECT_TRUE(contains(node.bounds, bounds[primitive]));
        }
      } else {
        EXPECT_TRUE(contains(node.bounds, tree.nodes[node.left].bounds));
        EXPECT_TRUE(contains(node.bounds, tree.nodes[node.right].bounds));
      }
    }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
    EXPECT_EQ(tree.nodes.size(), 2 * leaves - 1);
    EXPECT_LE(tree.depth(), kMaxTreeDepth);
  }
}

// cut_size stops the tree at ranges of that size: the same splits above them as a full build
// (so Ray-Strips cuts the same sub-meshes), every range of at most cut_size a leaf.
TEST(SahBuilder, CutSizeStopsAtTheRangesAFullBuildWouldCutThere) {
  const Scene scene = make_builtin_scene("builtin:sphere:20k");
  const std::vector<Bounds3> bounds = triangle_bounds(scene.mesh);
  constexpr std::uint32_t kCut = 256;
  SahOptions full;
  const BuildTree whole = build_sah_tree(bounds, full);
  SahOptions stopped = full;
  stopped.cut_size = kCut;
  const BuildTree cut = build_sah_tree(bounds, stopped);
  // The ranges at the first node of at most kCut primitives, as sets, on each tree.
  const auto pieces = [](const BuildTree& tree) {
    std::vector<std::vector<std::uint32_t>> found;
    std::function<std::vector<std::uint32_t>(std::uint32_t)> members = [&](std::uint32_t node) {
      const BuildNode& n = tree.nodes[node];
      if (n.leaf()) return std::vector<std::uint32_t>(tree.primitive_order.begin() + n.first,
                                                      tree.primitive_order.begin() + n.first + n.count);
      std::vector<std::uint32_t> all = members(n.left);
      const std::vector<std::uint32_t> right = members(n.right);
      all.insert(all.end(), right.begin(), right.end());
      return all;
    };
    std::function<void(std::uint32_t)> visit = [&](std::uint32_t node) {
      std::vector<std::uint32_t> all = members(node);
      if (all.size() <= kCut || tree.nodes[node].leaf()) {
        std::sort(all.begin(), all.end());
        found.push_back(all);
        return;
      }
      visit(tree.nodes[node].left);
      visit(tree.nodes[node].right);
    };
    visit(0);
    return found;
  };
  const auto expected = pieces(whole);
  EXPECT_EQ(pieces(cut), expected);
  EXPECT_GT(expected.size(), 20u);
  for (const BuildNode& node : cut.nodes) {
    if (node.leaf()) {
      EXPECT_LE(node.count, kCut);
    }
  }
  EXPECT_LT(cut.nodes.size(), whole.nodes.size() / 10);
}

// Wald's binned SAH written the plain way, one primitive and one axis at a time: one set of
// bins, scalar sweeps, the first cheapest plane in axis then bin order, std::partition. The
// builder bins in SIMD, deals a range to several sets of bins in turn, sweeps the three axes
// in lanes and partitions without std::partition: each must leave the tree as this one is.
struct PlainSahNode {
  Bounds3 bounds;
  std::vector<std::uint32_t> leaf;  // the ids, in leaf order; empty for an inner node
};

void plain_sah(std::vector<SahReference>& refs, std::uint32_t first, std::uint32_t count, const Bounds3& bounds,
               std::uint32_t depth, const SahOptions& options, std::vector<PlainSahNode>& preorder) {
  const auto centroid = [](const SahReference& r) { return (r.bounds.lower + r.bounds.upper) * 0.5f; };
  const auto half_area = [](const Bounds3& b) {
    if (b.empty()) return 0.0f;
    const glm::vec3 e = b.extent();
    return e.x * e.y + e.y * e.z + e.z * e.x;
  };
  const auto blocks = [&](std::uint32_t n) { return float((n + options.block_size - 1) / options.block_size); };
  const auto leaf = [&] {
    PlainSahNode node{bounds, {}};
    for (std::uint32_t i = first; i < first + count; ++i) node.leaf.push_back(refs[i].id);
    preorder.push_back(node);
  };
  if (count == 1 || count <= options.cut_size) return leaf();
  Bounds3 centroids;
  for (std::uint32_t i = first; i < first + count; ++i) centroids.extend(centroid(refs[i]));
  const std::uint32_t bins = options.bins;
  float scale[3];
  for (int axis = 0; axis < 3; ++axis) {
    const float extent = centroids.upper[axis] - centroids.lower[axis];
    scale[axis] = extent > 0.0f ? float(bins) * (1.0f - 1e-6f) / extent : 0.0f;
  }
  const auto bin_of = [&](const SahReference& r, int axis) {
    const int bin = int((centroid(r)[axis] - centroids.lower[axis]) * scale[axis]);
    return std::uint32_t(std::clamp(bin, 0, int(bins) - 1));
  };
  int best_axis = -1;
  std::uint32_t best_bin = 0;
  float best_cost = std::numeric_limits<float>::infinity();
  std::vector<Bounds3> best_boxes;
  if (depth < 64) {
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<Bounds3> box(bins);
      std::vector<std::uint32_t> in_bin(bins, 0);
      for (std::uint32_t i = first; i < first + count; ++i) {
        box[bin_of(refs[i], axis)].extend(refs[i].bounds);
        ++in_bin[bin_of(refs[i], axis)];
      }
      if (!(centroids.upper[axis] > centroids.lower[axis])) continue;
      for (std::uint32_t plane = 0; plane + 1 < bins; ++plane) {
        Bounds3 left, right;
        std::uint32_t left_count = 0, right_count = 0;
        for (std::uint32_t b = 0; b <= plane; ++b) left.extend(box[b]), left_count += in_bin[b];
        for (std::uint32_t b = bins - 1; b > plane; --b) right.extend(box[b]), right_count += in_bin[b];
        if (left_count == 0 || right_count == 0) continue;
        const float cost = half_area(left) * blocks(left_count) + half_area(right) * blocks(right_count);
        if (cost < best_cost) best_axis = axis, best_bin = plane, best_cost = cost, best_boxes = box;
      }
    }
  }
  const float leaf_cost = options.intersection_cost * blocks(count);
  const float split_cost = options.traversal_cost + options.intersection_cost * best_cost / half_area(bounds);
  if (count <= options.max_leaf_size && (best_axis < 0 || leaf_cost <= split_cost)) return leaf();
  preorder.push_back({bounds, {}});
  std::uint32_t middle = first + count / 2;
  Bounds3 left_bounds, right_bounds;
  if (best_axis >= 0) {
    middle = std::uint32_t(std::partition(refs.begin() + first, refs.begin() + first + count,
                                          [&](const SahReference& r) { return bin_of(r, best_axis) <= best_bin; }) -
                           refs.begin());
    for (std::uint32_t b = 0; b < bins; ++b) (b <= best_bin ? left_bounds : right_bounds).extend(best_boxes[b]);
  } else {
    for (std::uint32_t i = first; i < first + count; ++i) (i < middle ? left_bounds : right_bounds).extend(refs[i].bounds);
  }
  plain_sah(refs, first, middle - first, left_bounds, depth + 1, options, preorder);
  plain_sah(refs, middle, first + count - middle, right_bounds, depth + 1, options, preorder);
}

TEST(SahBuilder, BuildsTheTreeAPlainBinnedSahBuilds) {
  // Clusters of small boxes (ranges binned in sets of bins, in parallel above 65,536), and
  // stacks of boxes with one centroid (no plane separates them: the range is halved).
  std::mt19937 random(2026);
  const auto uniform = [&] { return std::uniform_real_distribution<float>(0.0f, 1.0f)(random); };
  std::vector<Bounds3> boxes;
  for (int cluster = 0; cluster < 40; ++cluster) {
    const glm::vec3 centre(uniform() * 100.0f + 1.0f, uniform() * 30.0f + 1.0f, uniform() * 60.0f + 1.0f);
    const float spread = 0.5f + uniform() * 8.0f;
    for (int i = 0; i < 1800; ++i) {
      const glm::vec3 at = centre + spread * glm::vec3(uniform(), uniform(), uniform());
      Bounds3 box;
      box.extend(at);
      box.extend(at + 0.3f * glm::vec3(uniform(), uniform(), uniform()));
      boxes.push_back(box);
    }
    for (int i = 0; i < 20; ++i) boxes.push_back(Bounds3{centre, centre + glm::vec3(1.0f)});
  }
  for (const SahOptions& options :
       {SahOptions{.max_leaf_size = 14, .bins = 16, .traversal_cost = 7.0f},
        SahOptions{.max_leaf_size = 4, .bins = 32, .block_size = 4}, SahOptions{.max_leaf_size = 3, .bins = 8, .block_size = 3},
        SahOptions{.max_leaf_size = 8, .bins = 64, .cut_size = 200}}) {
    const BuildTree tree = build_sah_tree(boxes, options);
    std::vector<PlainSahNode> built;
    std::function<void(std::uint32_t)> visit = [&](std::uint32_t index) {
      const BuildNode& node = tree.nodes[index];
      built.push_back({node.bounds, {}});
      if (!node.leaf()) return visit(node.left), visit(node.right);
      built.back().leaf.assign(tree.primitive_order.begin() + node.first, tree.primitive_order.begin() + node.first + node.count);
    };
    visit(0);
    std::vector<SahReference> refs;
    Bounds3 all;
    for (std::uint32_t i = 0; i < boxes.size(); ++i) refs.push_back({boxes[i], i, 0}), all.extend(boxes[i]);
    std::vector<PlainSahNode> expected;
    plain_sah(refs, 0, std::uint32_t(refs.size()), all, 1, options, expected);
    ASSERT_EQ(built.size(), expected.size()) << "leaves of " << options.max_leaf_size << ", " << options.bins << " bins";
    std::size_t differing = 0;
    for (std::size_t i = 0; i < built.size(); ++i) {
      differing += built[i].leaf != expected[i].leaf || built[i].bounds.lower != expected[i].bounds.lower ||
                   built[i].bounds.upper != expected[i].bounds.upper;
    }
    EXPECT_EQ(differing, 0u) << "leaves of " << options.max_leaf_size << ", " << options.bins << " bins";
  }
}

TEST(SahBuilder, CoincidentCentroidsStillSplitAndBadOptionsAreErrors) {
  std::vector<Bounds3> same(100);
  for (Bounds3& b : same) {
    b.extend(glm::vec3(-1.0f));
    b.extend(glm::vec3(1.0f));
  }
  const BuildTree tree = build_sah_tree(same, SahOptions{});
  for (const BuildNode& node : tree.nodes) {
    if (node.leaf()) {
      EXPECT_LE(node.count, 4u);
    }
  }
  SahOptions bad;
  bad.max_leaf_size = 17;
  EXPECT_THROW(build_sah_tree(same, bad), std::invalid_argument);
  EXPECT_THROW(build_sah_tree(std::span<const Bounds3>{}, SahOptions{}), std::invalid_argument);
  EXPECT_THROW(build_sah_tree(LargeArray<SahReference>{}, SahOptions{}), std::invalid_argument);
}

struct Agreement {
  double hit = 0.0;
  std::size_t rays = 0;
};

Agreement agreement(const Scene& scene, const Accelerator& accelerator, RaySetKind kind, std::size_t count) {
  AcceleratorOptions robust;
  robust.embree.mode = EmbreeMode::robust;
  const auto reference = make_accelerator(scene.mesh, robust);
  const RaySet rays = make_ray_set(kind, scene, *reference, count);
  const auto expected = trace_ray_set(*reference, rays);
  const auto actual = trace_ray_set(accelerator, rays);
  std::size_t same = 0;
  for (std::size_t b = 0; b < rays.batches.size(); ++b) {
    for (std::size_t i = 0; i < rays.batches[b]->count; ++i) same += expected[b]->is_hit(i) == actual[b]->is_hit(i);
  }
  return {double(same) / double(rays.count()), rays.count()};
}

class BvhAgreesWithEmbree : public ::testing::TestWithParam<std::string> {};

TEST_P(BvhAgreesWithEmbree, OnAtLeast9999PerMyriadOfRays) {
  const Scene scene = load_scene({GetParam(), 0});
  for (const std::uint32_t width : {2u, 8u}) {
    BvhOptions options;
    options.width = width;
    const auto bvh = make_bvh_accelerator(scene.mesh, options);
    for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::random, RaySetKind::diffuse, RaySetKind::shadow}) {
      const Agreement result = agreement(scene, *bvh, kind, 20000);
      EXPECT_GE(result.hit, 0.9999) << to_string(kind) << " width " << width << " on " << GetParam();
      EXPECT_GT(result.rays, 10000u);
    }
  }
}

TEST(Bvh, AxisParallelRaysThroughBoxFacesAndEdges) {
  // Rays along +-x, +-y, +-z on a lattice that puts many of them exactly on the planes of
  // an axis-aligned box mesh's faces, edges and corners (zero direction components, origins
  // on slab planes): every such ray that Embree robust sees hit must hit for both widths.
  const Scene stadium = make_builtin_scene("builtin:stadium:2000");
  AcceleratorOptions robust;
  robust.embree.mode = EmbreeMode::robust;
  const auto reference = make_accelerator(stadium.mesh, robust);
  RayBatch rays(4096);
  const float coordinates[] = {-500.0f, -250.0f, 0.0f, 0.5f, 250.0f, 500.0f};
  for (int axis = 0; axis < 3; ++axis) {
    for (const float sign : {-1.0f, 1.0f}) {
      for (const float a : coordinates) {
        for (const float b : coordinates) {
          const std::size_t i = rays.count++;
          glm::vec3 origin(0.0f), direction(0.0f);
          origin[(axis + 1) % 3] = a;
          origin[(axis + 2) % 3] = b;
          direction[axis] = sign;
          rays.origin_x[i] = origin.x, rays.origin_y[i] = origin.y, rays.origin_z[i] = origin.z;
          rays.direction_x[i] = direction.x, rays.direction_y[i] = direction.y, rays.direction_z[i] = direction.z;
          rays.tmin[i] = 0.0f;
          rays.tmax[i] = std::numeric_limits<float>::infinity();
          rays.flags[i] = ray_flags::alive;
          rays.kind[i] = RayKind::camera;
        }
      }
    }
  }
  HitBatch expected(4096), actual(4096);
  reference->intersect_closest(rays, expected, rays.all());
  for (const std::uint32_t width : {2u, 8u}) {
    BvhOptions options;
    options.width = width;
    const auto bvh = make_bvh_accelerator(stadium.mesh, options);
    bvh->intersect_closest(rays, actual, rays.all());
    for (std::size_t i = 0; i < rays.count; ++i) {
      EXPECT_TRUE(actual.is_hit(i)) << "width " << width << " ray " << i;  // the box is closed around the origins
      if (expected.is_hit(i) && actual.is_hit(i)) {
        EXPECT_NEAR(actual.t[i], expected.t[i], 1e-3f) << "width " << width << " ray " << i;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, BvhAgreesWithEmbree,
                         ::testing::Values("builtin:sphere:100k", "builtin:soup:50k",
                                           std::string(WAVETRACE_DATA_DIR) + "/bunny00.off"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return std::string(info.index == 0 ? "sphere" : info.index == 1 ? "soup" : "bunny");
                         });

// The tinybvh peer, where this build carries it (-DWAVETRACE_TINYBVH), answers what Embree
// answers: the same hit or miss (its Moeller-Trumbore test is not watertight: 999 in 1000) and
// the same distance where both hit the same triangle, for both of its layouts.
TEST(TinyBvhPeer, AgreesWithEmbreeWhereBuiltIn) {
  if (!tinybvh_built_in()) GTEST_SKIP() << "configured without -DWAVETRACE_TINYBVH";
  const Scene scene = make_builtin_scene("builtin:sphere:100k");
  for (const TinyBvhLayout layout : {TinyBvhLayout::bvh8, TinyBvhLayout::bvh2}) {
    AcceleratorOptions options;
    options.type = "tinybvh";
    options.tinybvh.layout = layout;
    const auto peer = make_accelerator(scene.mesh, options);
    EXPECT_EQ(peer->name(), "tinybvh-" + to_string(layout));
    EXPECT_GT(peer->memory().hierarchy, 0u);
    for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::random, RaySetKind::diffuse, RaySetKind::shadow}) {
      const Agreement result = agreement(scene, *peer, kind, 20000);
      EXPECT_GE(result.hit, 0.999) << to_string(kind) << " " << to_string(layout);
    }
    const auto reference = make_accelerator(scene.mesh, AcceleratorOptions{});
    const testing::Agreement close =
        testing::compare_on_rays(scene, *reference, *peer, RaySetKind::primary, 20000, 1e-4f, 1e-3f);
    EXPECT_GT(close.same_primitive, close.rays / 5) << to_string(layout);  // the sphere fills 29% of the frame
    EXPECT_LE(close.far_t, close.rays / 1000) << to_string(layout);
    EXPECT_LE(close.far_uv, close.rays / 1000) << to_string(layout);
  }
}

TEST(Bvh, AnyHitAgreesWithClosestHitOnOcclusion) {
  const Scene scene = make_builtin_scene("builtin:default:20000");
  const auto reference = make_accelerator(scene.mesh, AcceleratorOptions{});
  for (const std::uint32_t width : {2u, 8u}) {
    BvhOptions options;
    options.width = width;
    const auto bvh = make_bvh_accelerator(scene.mesh, options);
    for (const RaySetKind kind : {RaySetKind::shadow, RaySetKind::random}) {
      const RaySet rays = make_ray_set(kind, scene, *reference, 20000);
      for (const auto& batch : rays.batches) {
        HitBatch closest(batch->capacity()), any(batch->capacity());
        bvh->intersect_closest(*batch, closest, batch->all());
        bvh->intersect_any(*batch, any, batch->all());
        for (std::size_t i = 0; i < batch->count; ++i) ASSERT_EQ(closest.is_hit(i), any.is_hit(i)) << i;
      }
    }
  }
}

TEST(Bvh, EveryLayoutGivesIdenticalHits) {
  const Scene scene = make_builtin_scene("builtin:sphere:50k");
  const auto reference = make_accelerator(scene.mesh, AcceleratorOptions{});
  const RaySet rays = make_ray_set(RaySetKind::random, scene, *reference, 20000);
  const auto baseline = trace_ray_set(*make_bvh_accelerator(scene.mesh, BvhOptions{}), rays);
  // The same tree in another node or triangle order: bit-identical answers.
  for (const auto& [layout, order] : {std::pair{NodeLayout::breadth_first, TriangleOrder::input},
                                      std::pair{NodeLayout::van_emde_boas, TriangleOrder::input},
                                      std::pair{NodeLayout::depth_first, TriangleOrder::leaf},
                                      std::pair{NodeLayout::van_emde_boas, TriangleOrder::leaf}}) {
    BvhOptions options;
    options.layout = layout;
    options.triangle_order = order;
    const auto hits = trace_ray_set(*make_bvh_accelerator(scene.mesh, options), rays);
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
        ASSERT_EQ(hits[b]->primitive[i], baseline[b]->primitive[i]) << to_string(layout) << " " << to_string(order);
        ASSERT_EQ(hits[b]->t[i], baseline[b]->t[i]) << to_string(layout) << " " << to_string(order);
      }
    }
  }
  // Morton order and other leaf sizes change the tree: same hits, the same distance up to
  // rounding (a ray through a shared edge may report either triangle).
  struct Variant {
    TriangleOrder order;
    std::uint32_t leaf_size, width;
  };
  for (const Variant& variant : {Variant{TriangleOrder::morton, 4, 2}, Variant{TriangleOrder::input, 1, 2},
                                 Variant{TriangleOrder::input, 16, 2}, Variant{TriangleOrder::input, 4, 8},
                                 Variant{TriangleOrder::leaf, 4, 8}}) {
    BvhOptions options;
    options.triangle_order = variant.order;
    options.max_leaf_size = variant.leaf_size;
    options.width = variant.width;
    const auto hits = trace_ray_set(*make_bvh_accelerator(scene.mesh, options), rays);
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
        ASSERT_EQ(hits[b]->is_hit(i), baseline[b]->is_hit(i));
        if (hits[b]->is_hit(i)) {
          ASSERT_NEAR(hits[b]->t[i], baseline[b]->t[i], 1e-5f);
        }
      }
    }
  }
}

TEST(Bvh, MemoryIsNodesIndicesAndTheIndexedFaceSet) {
  const Scene scene = make_builtin_scene("builtin:sphere:20k");
  const auto bvh = make_bvh_accelerator(scene.mesh, BvhOptions{});
  const MemoryReport memory = bvh->memory();
  const std::size_t triangles = scene.mesh.triangle_count();
  EXPECT_EQ(memory.geometry, triangles * 12 + scene.mesh.vertex_count() * 12);
  EXPECT_EQ((memory.hierarchy - triangles * 4) % 32, 0u);  // whole 32-byte nodes
  EXPECT_LT(memory.hierarchy - triangles * 4, 2 * triangles * 32);
  EXPECT_EQ(memory.other, 0u);
  BvhOptions morton;
  morton.triangle_order = TriangleOrder::morton;
  EXPECT_EQ(make_bvh_accelerator(scene.mesh, morton)->memory().other, triangles * 4);  // the input-id map
  BvhOptions leaf;
  leaf.triangle_order = TriangleOrder::leaf;
  const MemoryReport leaf_memory = make_bvh_accelerator(scene.mesh, leaf)->memory();
  EXPECT_EQ(leaf_memory.hierarchy, memory.hierarchy - triangles * 4);  // no leaf index array
  EXPECT_EQ(leaf_memory.other, triangles * 4);
  EXPECT_GE(bvh->build().peak_bytes, memory.total());
}

TEST(Bvh, NoRayEscapesTheClosedSphere) {
  const Scene scene = make_builtin_scene("builtin:sphere:200k");
  const LeakReport report = run_leak_bench(
      scene, {parse_accelerator_spec("bvh", Config{}), parse_accelerator_spec("bvh:width=8", Config{})}, 200000, 0);
  ASSERT_EQ(report.results.size(), 2u);
  EXPECT_EQ(report.results[0].escaped, 0u);
  EXPECT_EQ(report.results[1].escaped, 0u);
  EXPECT_GT(report.inside_points, 1000u);
}

TEST(LeakBench, RefusesAnOpenMesh) {
  const Scene terrain = make_builtin_scene("builtin:terrain:2000");
  try {
    run_leak_bench(terrain, {parse_accelerator_spec("bvh", Config{})}, 1000, 1);
    FAIL();
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("boundary"), std::string::npos) << error.what();
  }
}

TEST(AccelBench, ReportsEveryFieldAgainstTheChosenReference) {
  const Scene scene = make_builtin_scene("builtin:sphere:5000");
  AccelBenchRequest request;
  request.accelerators = {parse_accelerator_spec("embree", Config{}), parse_accelerator_spec("bvh:layout=veb", Config{})};
  request.count = 5000;
  request.repeats = 3;
  request.threads = 1;
  request.reference = parse_accelerator_spec("embree:mode=robust", Config{});
  const AccelBenchReport report = run_accel_bench(scene, request);
  EXPECT_EQ(report.reference, "embree:mode=robust");
  ASSERT_EQ(report.results.size(), 2u);
  EXPECT_GE(report.results[0].hit_agreement, 0.999);  // default Embree against robust Embree
  EXPECT_EQ(report.results[0].mrays_per_s_runs.size(), 3u);
  EXPECT_GT(report.results[1].mrays_per_s, 0.0);
  // Interleaved rounds: each result's ratio to the first is the median of run k against run k.
  EXPECT_TRUE(report.interleaved);
  for (const AccelBenchResult& result : report.results) {
    ASSERT_EQ(result.vs_first_runs.size(), 3u);
    std::vector<double> ratios;
    for (std::size_t run = 0; run < 3; ++run) {
      ratios.push_back(result.mrays_per_s_runs[run] / report.results[0].mrays_per_s_runs[run]);
      EXPECT_DOUBLE_EQ(result.vs_first_runs[run], ratios.back());
    }
    std::sort(ratios.begin(), ratios.end());
    EXPECT_DOUBLE_EQ(result.vs_first, ratios[1]);
  }
  EXPECT_DOUBLE_EQ(report.results[0].vs_first, 1.0);
  const nlohmann::json json = to_json(report);
  for (const char* key : {"accel", "bytes", "bytes_per_triangle", "parts", "build_seconds", "build_peak_accounted_bytes",
                          "mrays_per_s", "hit_agreement", "prim_agreement", "t_error_max", "t_error_mean"}) {
    EXPECT_TRUE(json["results"][1].contains(key)) << key;
  }
  EXPECT_EQ(json["results"][1]["accel"], "bvh:layout=veb");
  EXPECT_EQ(json["results"][1]["vs_first_runs"].size(), 3u);
  EXPECT_NE(to_csv(report).find("bvh:layout=veb"), std::string::npos);
  EXPECT_NE(to_table(report).find("3 rounds, each accelerator once a round in turn"), std::string::npos);

  // One at a time: the same fields, no rounds to pair, the ratio of the medians.
  request.one_at_a_time = true;
  const AccelBenchReport apart = run_accel_bench(scene, request);
  EXPECT_FALSE(apart.interleaved);
  ASSERT_EQ(apart.results.size(), 2u);
  EXPECT_EQ(apart.results[1].mrays_per_s_runs.size(), 3u);
  EXPECT_TRUE(apart.results[1].vs_first_runs.empty());
  EXPECT_DOUBLE_EQ(apart.results[1].vs_first, apart.results[1].mrays_per_s / apart.results[0].mrays_per_s);
  EXPECT_EQ(apart.results[1].hit_agreement, report.results[1].hit_agreement);
  EXPECT_NE(to_table(apart).find("3 runs, one accelerator at a time"), std::string::npos);
}

TEST(AccelBench, BadSpecsNameTheProblem) {
  EXPECT_THROW(parse_accelerator_spec("octree", Config{}), ConfigError);
  EXPECT_THROW(parse_accelerator_spec("bvh:layout=spiral", Config{}), ConfigError);
  EXPECT_THROW(parse_accelerator_spec("bvh:leaf_size=99", Config{}), ConfigError);
  EXPECT_THROW(parse_accelerator_spec("bvh:veb", Config{}), ConfigError);
  EXPECT_EQ(parse_accelerator_spec("bvh:leaf_size=8:layout=veb", Config{}).options.bvh.max_leaf_size, 8u);
}

// The binary tree keeps the papers' leaves of four; the 8-wide tree's leaves are up to four
// blocks of four, unless a size is asked.
TEST(AccelBench, EachWidthHasItsOwnLeavesUnlessOneIsAsked) {
  EXPECT_EQ(parse_accelerator_spec("bvh", Config{}).options.bvh.leaf_triangles(), 4u);
  EXPECT_EQ(parse_accelerator_spec("bvh:width=8", Config{}).options.bvh.leaf_triangles(), 16u);
  EXPECT_EQ(parse_accelerator_spec("bvh:width=8:leaf_size=4", Config{}).options.bvh.leaf_triangles(), 4u);
  EXPECT_EQ(parse_accelerator_spec("bvh:leaf_size=2", Config{}).options.bvh.leaf_triangles(), 2u);
  // Built: leaves of several blocks take fewer nodes, and the same triangles' blocks.
  const Scene scene = make_builtin_scene("builtin:room:20k");
  const auto bytes = [&](const std::string& spec) {
    return make_bvh_accelerator(scene.mesh, parse_accelerator_spec(spec, Config{}).options.bvh)->memory().total();
  };
  EXPECT_LT(bytes("bvh:width=8"), bytes("bvh:width=8:leaf_size=4"));
  EXPECT_EQ(bytes("bvh:width=8"), bytes("bvh:width=8:leaf_size=16"));
}

}  // namespace
}  // namespace wavetrace
