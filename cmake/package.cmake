# `cmake --install build --prefix P`: headers under P/include/wavetrace/, the layer libraries,
# and a CMake package exporting wavetrace::wavetrace (and wavetrace::LAYER) for
# find_package(wavetrace); its Debian dependencies are found again through find_dependency.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(wavetrace_layers kernels memory scene accel stages pipeline setup distribute bench)
foreach(layer ${wavetrace_layers})
  set_target_properties(wavetrace_${layer} PROPERTIES EXPORT_NAME ${layer})
  add_library(wavetrace::${layer} ALIAS wavetrace_${layer})
endforeach()
set_target_properties(wavetrace_library PROPERTIES EXPORT_NAME wavetrace)

install(TARGETS wavetrace_kernels wavetrace_memory wavetrace_scene wavetrace_accel wavetrace_stages wavetrace_pipeline wavetrace_setup wavetrace_distribute wavetrace_bench
                wavetrace_library
        EXPORT wavetraceTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/wavetrace/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/wavetrace
        FILES_MATCHING PATTERN "*.hpp")
install(FILES ${PROJECT_BINARY_DIR}/include/wavetrace/build_config.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/wavetrace)
# The report's chart writer, which `bench report` runs with Debian's python.
install(FILES ${PROJECT_SOURCE_DIR}/bench/report.py ${PROJECT_SOURCE_DIR}/bench/plot_accel.py
        DESTINATION ${CMAKE_INSTALL_DATADIR}/wavetrace)
if(WAVETRACE_BUILD_APP)
  install(TARGETS wavetrace RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

set(wavetrace_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/wavetrace)
install(EXPORT wavetraceTargets NAMESPACE wavetrace:: DESTINATION ${wavetrace_cmake_dir})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/wavetraceConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/wavetraceConfig.cmake INSTALL_DESTINATION ${wavetrace_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/wavetraceConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/wavetraceConfig.cmake ${PROJECT_BINARY_DIR}/wavetraceConfigVersion.cmake
        DESTINATION ${wavetrace_cmake_dir})
