// Fuzzes load_mesh_file on one format (WAVETRACE_FUZZ_EXTENSION: ".off", ".ply", ".obj" or
// ".stl"): any input loads or throws SceneError; anything else (a crash, a sanitizer report,
// another exception, a hang) is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_input_file.hpp"
#include "wavetrace/scene/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static wavetrace::fuzzing::FuzzInputFile file(WAVETRACE_FUZZ_EXTENSION);
  const std::string& path = file.write(data, size);
  try {
    const wavetrace::LoadedMesh loaded = wavetrace::load_mesh_file(path);
    // What a loaded mesh promises its users: every index names a vertex.
    for (const glm::uvec3& triangle : loaded.mesh.triangles) {
      for (int k = 0; k < 3; ++k) {
        if (triangle[k] >= loaded.mesh.positions.size()) __builtin_trap();
      }
    }
  } catch (const wavetrace::SceneError&) {
  }
  return 0;
}
