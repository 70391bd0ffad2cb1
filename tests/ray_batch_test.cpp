// Ray and hit batch layout: alignment, capacity, optional columns, pooling.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "wavetrace/memory/batch_pool.hpp"
#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {
namespace {

bool aligned(const void* pointer) { return reinterpret_cast<std::uintptr_t>(pointer) % kColumnAlignment == 0; }

TEST(RayBatch, EveryColumnIsCacheLineAligned) {
  for (std::size_t capacity : {1u, 3u, 17u, 4096u}) {
    RayBatch rays(capacity);
    const void* columns[] = {rays.origin_x, rays.origin_y, rays.origin_z, rays.direction_x, rays.direction_y,
                             rays.direction_z, rays.tmin, rays.tmax, rays.pixel, rays.sample, rays.depth, rays.kind,
                             rays.throughput_r, rays.throughput_g, rays.throughput_b, rays.flags};
    for (const void* column : columns) EXPECT_TRUE(aligned(column)) << "capacity " << capacity;
    HitBatch hits(capacity);
    for (const void* column : {static_cast<const void*>(hits.t), static_cast<const void*>(hits.primitive),
                               static_cast<const void*>(hits.u), static_cast<const void*>(hits.v)}) {
      EXPECT_TRUE(aligned(column));
    }
  }
}

TEST(RayBatch, ColumnsDoNotOverlap) {
  RayBatch rays(33);
  for (std::size_t i = 0; i < 33; ++i) {
    rays.origin_x[i] = 1.0f;
    rays.origin_y[i] = 2.0f;
    rays.flags[i] = 7;
    rays.depth[i] = 9;
  }
  rays.throughput_b[32] = 5.0f;
  rays.pixel[32] = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < 33; ++i) {
    EXPECT_EQ(rays.origin_x[i], 1.0f);
    EXPECT_EQ(rays.origin_y[i], 2.0f);
    EXPECT_EQ(rays.flags[i], 7);
    EXPECT_EQ(rays.depth[i], 9);
  }
}

TEST(RayBatch, OptionalColumnsAppearOnRequestAndCopy) {
  RayBatch source(8), target(8);
  EXPECT_FALSE(source.has_approx_hit());
  EXPECT_FALSE(source.has_sort_key());
  source.enable_approx_hit();
  source.enable_sort_key();
  EXPECT_TRUE(aligned(source.approx_hit_x));
  EXPECT_TRUE(aligned(source.sort_key));
  source.approx_hit_z[3] = 4.5f;
  source.sort_key[3] = 0x123456789ull;
  source.pixel[3] = 77;
  target.copy_ray(0, source, 3);
  ASSERT_TRUE(target.has_approx_hit());
  EXPECT_EQ(target.approx_hit_z[0], 4.5f);
  EXPECT_EQ(target.sort_key[0], 0x123456789ull);
  EXPECT_EQ(target.pixel[0], 77u);
}

// The column lists are the one declaration: the visitor sees every present column once, in
// layout order, and the bytes a ray costs are the sum of its columns' element sizes.
TEST(RayBatch, ColumnVisitorAndBytesFollowTheOneList) {
  RayBatch rays(8);
  std::size_t columns = 0, bytes = 0;
  const auto count = [&](const char*, void* column, std::size_t element_bytes) {
    EXPECT_TRUE(aligned(column));
    ++columns;
    bytes += element_bytes;
  };
  rays.for_each_column(count);
  EXPECT_EQ(columns, 16u);
  EXPECT_EQ(bytes, RayBatch::kBytesPerRay);
  EXPECT_EQ(RayBatch::kBytesPerRay, 13 * 4 + 2 + 1 + 1u);
  rays.enable_approx_hit();
  rays.enable_sort_key();
  columns = bytes = 0;
  rays.for_each_column(count);
  EXPECT_EQ(columns, 20u);
  EXPECT_EQ(bytes, RayBatch::kBytesPerRay + RayBatch::kApproxHitBytesPerRay + RayBatch::kSortKeyBytesPerRay);
  EXPECT_EQ(HitBatch::kBytesPerHit, 11 * 4u);
  // The visitor names the columns as the class does, first to last.
  std::vector<std::string> names;
  rays.for_each_column([&](const char* name, void*, std::size_t) { names.emplace_back(name); });
  EXPECT_EQ(names.front(), "origin_x");
  EXPECT_EQ(names.back(), "sort_key");
}

TEST(BatchPool, ReusesReleasedBatches) {
  BatchPool pool(64);
  Batch* first = pool.acquire();
  first->rays.count = 10;
  pool.release(first);
  Batch* again = pool.acquire();
  EXPECT_EQ(again, first);
  EXPECT_EQ(again->rays.count, 0u);
  EXPECT_EQ(again->rays.capacity(), 64u);
  Batch* second = pool.acquire();
  EXPECT_NE(second, first);
  EXPECT_EQ(pool.allocated(), 2u);
  pool.release(again);
  pool.release(second);
}

}  // namespace
}  // namespace wavetrace
