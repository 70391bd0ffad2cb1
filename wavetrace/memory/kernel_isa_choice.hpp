// Which set of walks (kernels/kernel_isa.hpp) a new accelerator runs: the best this CPU has,
// as Embree chooses, unless WAVETRACE_ISA or accel.isa forces one.
#pragma once

#include <string_view>
#include <vector>

#include "wavetrace/kernels/kernel_isa.hpp"

namespace wavetrace {

// "avx2" for the default build's baseline, the -march text for another (x86-64-v2, native);
// "avx512".
std::string_view to_string(KernelIsa isa);

// The sets this build carries and this CPU runs, the best last.
std::vector<KernelIsa> runnable_kernel_isas();

// "auto": WAVETRACE_ISA where set, else the best runnable; or a set by its name. Throws
// std::invalid_argument naming the problem: a name no set has, or a set this build lacks or
// this CPU cannot run.
KernelIsa parse_kernel_isa(std::string_view name);

// parse_kernel_isa("auto"), asked once per process: what a new accelerator walks with.
KernelIsa default_kernel_isa();

}  // namespace wavetrace
