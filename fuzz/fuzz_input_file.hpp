// libFuzzer hands a target bytes; wavetrace's loaders take paths, as a user's files reach
// them. Each input is written to one file in /dev/shm (memory, not disk), named with the
// extension the loader dispatches on, so a target runs the loader end to end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace wavetrace::fuzzing {

class FuzzInputFile {
 public:
  explicit FuzzInputFile(const std::string& extension)
      : path_("/dev/shm/wavetrace-fuzz-" + std::to_string(::getpid()) + extension) {}
  ~FuzzInputFile() { std::remove(path_.c_str()); }
  FuzzInputFile(const FuzzInputFile&) = delete;
  FuzzInputFile& operator=(const FuzzInputFile&) = delete;

  const std::string& write(const std::uint8_t* data, std::size_t size) {
    std::FILE* file = std::fopen(path_.c_str(), "wb");
    if (file == nullptr || (size > 0 && std::fwrite(data, 1, size, file) != size) || std::fclose(file) != 0) {
      std::perror(path_.c_str());
      std::abort();  // the machine, not the input: stop the run rather than report nonsense
    }
    return path_;
  }

 private:
  std::string path_;
};

}  // namespace wavetrace::fuzzing
