// Fuzzes saved worlds (.wtw): load_world, then rays traced through what loaded. Any input is
// a world that answers rays or a SectionFileError/SceneError/ConfigError naming the problem.
//
// A world's header, table and sections carry XXH3 checksums, so nearly every mutation would
// stop at the first check. The custom mutator below re-seals each mutated input (section,
// table and header checksums recomputed where they can be found) so that the fuzzer reaches
// what lies behind them: the accelerators' own section checks, as a crafted file would.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include <xxhash.h>

#include "fuzz/fuzz_input_file.hpp"
#include "wavetrace/memory/section_file_format.hpp"
#include "wavetrace/setup/world_file.hpp"

namespace {

namespace format = wavetrace::section_file;

void reseal(std::uint8_t* data, std::size_t size) {
  format::Header header;
  if (size < sizeof header) return;
  std::memcpy(&header, data, sizeof header);
  if (std::memcmp(header.magic, format::kMagic, sizeof header.magic) != 0) return;
  const std::uint64_t table_bytes = std::uint64_t{header.section_count} * sizeof(format::TableEntry);
  if (header.table_offset > size || table_bytes > size - header.table_offset) return;
  for (std::uint32_t i = 0; i < header.section_count; ++i) {
    std::uint8_t* at = data + header.table_offset + i * sizeof(format::TableEntry);
    format::TableEntry entry;
    std::memcpy(&entry, at, sizeof entry);
    if (entry.offset <= size && entry.size <= size - entry.offset) {
      entry.checksum = XXH3_64bits(data + entry.offset, entry.size);
      std::memcpy(at, &entry, sizeof entry);
    }
  }
  header.table_checksum = XXH3_64bits(data + header.table_offset, table_bytes);
  header.header_checksum = XXH3_64bits(&header, format::kHeaderChecksummedBytes);
  std::memcpy(data, &header, sizeof header);
}

// Rays from outside the scene's box towards points across it, closest and any hit.
void trace_some_rays(const wavetrace::Accelerator& accelerator, const wavetrace::Bounds3& bounds) {
  constexpr std::size_t kRays = 64;
  wavetrace::RayBatch rays(kRays);
  wavetrace::HitBatch hits(kRays);
  const glm::vec3 centre = 0.5f * (bounds.lower + bounds.upper);
  const glm::vec3 extent = glm::max(bounds.upper - bounds.lower, glm::vec3(1e-3f));
  for (std::size_t i = 0; i < kRays; ++i) {
    const float a = float(i) / kRays;
    const glm::vec3 origin = centre + extent * glm::vec3(1.5f - 3.0f * a, 1.25f, 2.0f * a - 1.0f);
    const glm::vec3 target = centre + extent * glm::vec3(0.5f - a, -0.5f, 0.25f - 0.5f * a);
    rays.set_geometry(i, origin, target - origin, 0.0f, std::numeric_limits<float>::infinity());
    rays.flags[i] = wavetrace::ray_flags::alive;
    rays.kind[i] = wavetrace::RayKind::bounce;
  }
  rays.count = kRays;
  accelerator.intersect_closest(rays, hits, rays.all());
  accelerator.intersect_any(rays, hits, rays.all());
}

}  // namespace

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int /*seed*/) {
  size = LLVMFuzzerMutate(data, size, max_size);
  reseal(data, size);
  return size;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static wavetrace::fuzzing::FuzzInputFile file(".wtw");
  const std::string& path = file.write(data, size);
  try {
    const std::unique_ptr<wavetrace::LoadedWorld> world = wavetrace::load_world(path, std::nullopt, 1);
    if (!world->scene.bounds.empty()) trace_some_rays(*world->accelerator, world->scene.bounds);
  } catch (const wavetrace::SectionFileError&) {
  } catch (const wavetrace::SceneError&) {
  } catch (const wavetrace::ConfigError&) {
  }
  return 0;
}
