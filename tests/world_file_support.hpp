// What the saved-world tests share: temporary paths, whole-file reads and writes, a resealer
// that edits a section and recomputes the checksums, and the small room built, saved and
// rendered again from its file.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>
#include <xxhash.h>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/memory/section_file.hpp"
#include "wavetrace/memory/section_file_format.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/setup/world_file.hpp"

namespace wavetrace::world_testing {

namespace fs = std::filesystem;
using section_file::Header;
using section_file::TableEntry;

inline std::string temp_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "wavetrace_tests";
  fs::create_directories(dir);
  return (dir / (std::to_string(::getpid()) + "_" + name)).string();
}

inline std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

inline void write_all(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// Replaces a section's bytes in place (same size) and recomputes every checksum, so that a
// test reaches the check behind them (a wrong version, an offset out of bounds).
struct Resealer {
  std::string bytes;
  Header header{};
  std::vector<TableEntry> table;
  explicit Resealer(const std::string& path) : bytes(read_all(path)) {
    std::memcpy(&header, bytes.data(), sizeof(header));
    table.resize(header.section_count);
    std::memcpy(table.data(), bytes.data() + header.table_offset, table.size() * sizeof(TableEntry));
  }
  TableEntry& entry(const std::string& name) {
    for (TableEntry& e : table) {
      if (name == e.name) return e;
    }
    throw std::logic_error("no section " + name);
  }
  char* data(const std::string& name) { return bytes.data() + entry(name).offset; }
  void seal(const std::string& path) {
    for (TableEntry& e : table) {
      if (e.offset + e.size <= bytes.size()) e.checksum = XXH3_64bits(bytes.data() + e.offset, e.size);
    }
    std::memcpy(bytes.data() + header.table_offset, table.data(), table.size() * sizeof(TableEntry));
    header.table_checksum = XXH3_64bits(table.data(), table.size() * sizeof(TableEntry));
    header.header_checksum = XXH3_64bits(&header, section_file::kHeaderChecksummedBytes);
    std::memcpy(bytes.data(), &header, sizeof(header));
    write_all(path, bytes);
  }
};

inline std::string open_error(const std::string& path) {
  try {
    load_world(path);
  } catch (const SectionFileError& error) {
    return error.what();
  }
  return "(no error)";
}

inline Config small_render(const std::vector<std::string>& settings) {
  Config config;
  config.set("render.width=32");
  config.set("render.height=24");
  config.set("render.spp=1");
  config.set("render.threads=2");
  for (const std::string& s : settings) config.set(s);
  return config;
}

inline std::vector<float> render_with(const Config& config, const World& world) {
  const RenderPlan plan = plan_render(config);
  return render_image(plan, world, resolve_camera(plan.camera, world.scene)).image;
}

inline const Scene& room() {
  static const Scene scene = make_builtin_scene("builtin:room:20k");
  return scene;
}

// Builds `settings` over the room, saves it, and returns the fresh build's image.
inline std::vector<float> build_and_save(const std::vector<std::string>& settings, const std::string& path, bool proxy = false) {
  const Config config = small_render(settings);
  const RenderPlan plan = plan_render(config);
  const Scene& scene = room();
  const auto accelerator = build_world_accelerator(scene, plan.accelerator);
  const LightSampler lights(scene);
  std::unique_ptr<Proxy> simplified;
  if (proxy) simplified = std::make_unique<Proxy>(scene.mesh, plan.proxy, *accelerator);
  save_world(path, scene, lights, *accelerator, plan.accelerator.type, simplified.get(), config, {});
  return render_with(config, World{scene, *accelerator, lights, simplified.get()});
}

inline std::vector<float> render_loaded(const std::vector<std::string>& settings, const std::string& path) {
  const Config config = small_render(settings);
  const RenderPlan plan = plan_render(config);
  const std::unique_ptr<LoadedWorld> world = load_world(path, world_paging(plan), 2, CheckedPages::kept, world_holding(plan));
  const LoadedWorld& loaded = *world;
  return render_with(config, World{loaded.scene, *loaded.accelerator, *loaded.lights,
                                   plan.needs_proxy() ? loaded.proxy.get() : nullptr, loaded.file->pager()});
}

}  // namespace wavetrace::world_testing
