# Install rules and the exported CMake package: after
#   cmake --install <build> --prefix P
# a downstream project finds the libraries with
#   find_package(icd CONFIG REQUIRED)   # CMAKE_PREFIX_PATH=P
#   target_link_libraries(app PRIVATE icd::coupling)
# and includes the headers as <icd/<module>/...>.
include(CMakePackageConfigHelpers)

set(ICD_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/icd)
set(_icd_libs icd_mesh_core icd_mesh_io icd_fem icd_collision icd_coupling)
if(TARGET icd_mesh)
  list(APPEND _icd_libs icd_mesh)
  set(ICD_WITH_PREPROCESS ON)
else()
  set(ICD_WITH_PREPROCESS OFF)
endif()
install(TARGETS ${_icd_libs} EXPORT icdTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

# Public headers: the module folders under include/icd/ (as in the build
# tree's generated/icd/), and the generated config.hpp.
set(_icd_header_dirs fem collision coupling mesh/core mesh/io)
if(ICD_WITH_PREPROCESS)
  list(APPEND _icd_header_dirs mesh/pipeline mesh/spheres)
endif()
foreach(dir ${_icd_header_dirs})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/icd/${dir}
          FILES_MATCHING PATTERN "*.hpp")
endforeach()
install(FILES ${PROJECT_BINARY_DIR}/generated/icd/config.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/icd)

install(EXPORT icdTargets NAMESPACE icd:: DESTINATION ${ICD_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/icdConfig.cmake.in
  ${PROJECT_BINARY_DIR}/icdConfig.cmake INSTALL_DESTINATION ${ICD_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/icdConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/icdConfig.cmake ${PROJECT_BINARY_DIR}/icdConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/FindCHOLMOD.cmake ${PROJECT_SOURCE_DIR}/cmake/FindMETIS.cmake
        DESTINATION ${ICD_INSTALL_CMAKEDIR})

# icd-sweep (experiments/sweep/): installed beside the programs it runs (it
# looks them up in its own folder).
if(TARGET icd-sweep)
  install(TARGETS icd-sweep RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
