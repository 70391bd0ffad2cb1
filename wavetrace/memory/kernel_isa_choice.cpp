// The choice of walks: the CPU's features (cpu_support.hpp) against the sets this build has.
#include "wavetrace/memory/kernel_isa_choice.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "wavetrace/memory/cpu_support.hpp"

namespace wavetrace {

std::string_view to_string(KernelIsa isa) {
  if (isa == KernelIsa::avx512) return "avx512";
  if (WAVETRACE_AVX2 && !WAVETRACE_AVX512F) return "avx2";
  return WAVETRACE_ARCH;
}

std::vector<KernelIsa> runnable_kernel_isas() {
  std::vector<KernelIsa> sets = {KernelIsa::baseline};
  if (WAVETRACE_AVX512_DISPATCH && running_cpu_features().avx512) sets.push_back(KernelIsa::avx512);
  return sets;
}

namespace {

std::string names(const std::vector<KernelIsa>& sets) {
  std::string text;
  for (const KernelIsa isa : sets) text += (text.empty() ? "" : ", ") + std::string(to_string(isa));
  return text;
}

KernelIsa named_kernel_isa(std::string_view name, std::string_view source) {
  const std::vector<KernelIsa> sets = runnable_kernel_isas();
  for (const KernelIsa isa : sets) {
    if (name == to_string(isa)) return isa;
  }
  if (name == "avx512" && WAVETRACE_AVX512_DISPATCH) {
    throw std::invalid_argument(fmt::format("{} '{}': this CPU has no AVX-512 (F, VL, BW, DQ, CD); it runs {}", source,
                                            name, names(sets)));
  }
  if (name == "avx2" || name == "avx512") {
    throw std::invalid_argument(fmt::format("{} '{}': this build (-march={}) has only its {} walks", source, name,
                                            WAVETRACE_ARCH, to_string(KernelIsa::baseline)));
  }
  throw std::invalid_argument(fmt::format("{} '{}': expected auto, avx2 or avx512 (this CPU runs {})", source, name,
                                          names(sets)));
}

}  // namespace

KernelIsa parse_kernel_isa(std::string_view name) {
  if (name != "auto") return named_kernel_isa(name, "accel.isa");
  if (const char* forced = std::getenv("WAVETRACE_ISA"); forced != nullptr && *forced != '\0') {
    return named_kernel_isa(forced, "WAVETRACE_ISA");
  }
  return runnable_kernel_isas().back();
}

KernelIsa default_kernel_isa() {
  static const KernelIsa chosen = parse_kernel_isa("auto");
  return chosen;
}

}  // namespace wavetrace
