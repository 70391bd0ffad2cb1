# What -march=${WAVETRACE_ARCH} enables, asked of the compiler, written to
# wavetrace/build_config.hpp: the headers switch on it, so every translation unit (the
# library's and its consumers') sees one definition of each inline function.
include(CheckCXXSourceCompiles)
string(MAKE_C_IDENTIFIER "${WAVETRACE_ARCH}" wavetrace_arch_id)
set(CMAKE_REQUIRED_FLAGS "-march=${WAVETRACE_ARCH}")
foreach(feature AVX2 FMA BMI2 AVX512F)
  check_cxx_source_compiles("#ifndef __${feature}__\n#error\n#endif\nint main() { return 0; }"
                            WAVETRACE_${wavetrace_arch_id}_HAS_${feature})
  if(WAVETRACE_${wavetrace_arch_id}_HAS_${feature})
    set(WAVETRACE_${feature} 1)
  else()
    set(WAVETRACE_${feature} 0)
  endif()
endforeach()
unset(CMAKE_REQUIRED_FLAGS)
configure_file(${CMAKE_CURRENT_LIST_DIR}/build_config.hpp.in ${PROJECT_BINARY_DIR}/include/wavetrace/build_config.hpp @ONLY)
