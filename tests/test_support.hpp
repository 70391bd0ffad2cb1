// Helpers shared by the tests: temporary files, running the wavetrace binary, mesh volume.
#pragma once

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace::testing {

// AddressSanitizer reserves terabytes of shadow memory: tests that limit the address space
// (ulimit -v) cannot run under it.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
inline constexpr bool kAddressSanitizer = __has_feature(address_sanitizer);
#else
inline constexpr bool kAddressSanitizer = false;
#endif

// The volume a closed mesh encloses: positive when its faces point outward.
inline double signed_volume(const TriangleMesh& mesh) {
  double volume = 0.0;
  for (const glm::uvec3& t : mesh.triangles) {
    volume += glm::dot(glm::dvec3(mesh.positions[t.x]),
                       glm::cross(glm::dvec3(mesh.positions[t.y]), glm::dvec3(mesh.positions[t.z]))) / 6.0;
  }
  return volume;
}

inline std::string data_path(const std::string& name) { return std::string(WAVETRACE_DATA_DIR) + "/" + name; }

// A file under a fresh per-test temporary directory, holding `contents`.
inline std::string write_temp_file(const std::string& name, const std::string& contents) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "wavetrace_tests";
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / name;
  // ctest runs tests in parallel processes: write aside, then rename over atomically, so
  // a test never reads a file another is halfway through writing.
  const std::filesystem::path partial = dir / (name + "." + std::to_string(::getpid()) + ".partial");
  std::ofstream(partial, std::ios::binary) << contents;
  std::filesystem::rename(partial, path);
  return path.string();
}

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs `command` through the shell; exit_code -1 when a signal ended it.
inline CommandResult run_shell(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  while (std::size_t read = std::fread(buffer, 1, sizeof buffer, pipe)) result.output.append(buffer, read);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// Runs the wavetrace binary with `arguments` (shell syntax), after `limits` (shell commands
// such as "ulimit -v 300000;") when given.
inline CommandResult run_wavetrace(const std::string& arguments, const std::string& limits = "") {
  return run_shell(limits + " exec " + std::string(WAVETRACE_BINARY) + " " + arguments + " 2>&1");
}

// `wavetrace bench ARGUMENTS --json F`, F a fresh temporary file `name`: the report it wrote,
// after checking that the command succeeded and, when given, printed `printed`; null (and the
// test failed) when it did not succeed.
inline nlohmann::json run_bench_json(const std::string& name, const std::string& arguments,
                                     const std::string& printed = "") {
  const std::string json_path = write_temp_file(name, "");
  const CommandResult result = run_wavetrace("bench " + arguments + " --json " + json_path);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  if (result.exit_code != 0) return nullptr;
  EXPECT_NE(result.output.find(printed), std::string::npos) << result.output;
  return nlohmann::json::parse(std::ifstream(json_path));
}

}  // namespace wavetrace::testing
