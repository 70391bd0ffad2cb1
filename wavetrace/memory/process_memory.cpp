// Reads /proc/self/status, /proc/self/smaps_rollup and /proc/meminfo; each field is a line "Name:   1234 kB".
#include "wavetrace/memory/process_memory.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

namespace wavetrace {
namespace {

// The kB value of the line starting with `field` (e.g. "VmHWM:"), in bytes; 0 if absent.
std::size_t read_kilobyte_field(const char* path, const char* field) {
  std::ifstream file(path);
  std::string line;
  const std::size_t length = std::strlen(field);
  while (std::getline(file, line)) {
    if (line.compare(0, length, field) != 0) continue;
    unsigned long long kilobytes = 0;
    if (std::sscanf(line.c_str() + length, "%llu", &kilobytes) != 1) return 0;
    return static_cast<std::size_t>(kilobytes) * 1024;
  }
  return 0;
}

}  // namespace

ResidentMemory read_resident_memory() {
  return {read_kilobyte_field("/proc/self/status", "VmRSS:"), read_kilobyte_field("/proc/self/status", "VmHWM:")};
}

bool reset_peak_resident_memory() {
  std::FILE* file = std::fopen("/proc/self/clear_refs", "w");
  if (file == nullptr) return false;
  const bool written = std::fputs("5", file) >= 0;
  return std::fclose(file) == 0 && written;
}

std::size_t available_memory_bytes() { return read_kilobyte_field("/proc/meminfo", "MemAvailable:"); }

std::size_t anonymous_huge_page_bytes() { return read_kilobyte_field("/proc/self/smaps_rollup", "AnonHugePages:"); }

}  // namespace wavetrace
