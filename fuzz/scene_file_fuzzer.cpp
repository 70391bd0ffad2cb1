// Fuzzes load_scene_file: any TOML loads into a scene or throws SceneError. Objects may make
// at most 2000 triangles in all, so that a builtin of millions is refused (as it would be
// past the machine's memory) rather than built for seconds per input.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_input_file.hpp"
#include "wavetrace/scene/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static wavetrace::fuzzing::FuzzInputFile file(".toml");
  const std::string& path = file.write(data, size);
  try {
    wavetrace::load_scene_file(path, wavetrace::SceneFileLimits{.max_triangles = 2000});
  } catch (const wavetrace::SceneError&) {
  }
  return 0;
}
