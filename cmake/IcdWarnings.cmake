# icd::warnings: the warning flags every target of ours uses, plus the
# project-wide switches (asserts in optimized builds, sanitizers).
add_library(icd_warnings INTERFACE)
add_library(icd::warnings ALIAS icd_warnings)
target_compile_options(icd_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow=local -Wnon-virtual-dtor>)

if(ICD_ENABLE_ASSERTS)
  # Release speed, but assert() stays on: the test configuration.
  target_compile_options(icd_warnings INTERFACE -UNDEBUG)
endif()

if(ICD_SANITIZE)
  target_compile_options(icd_warnings INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(icd_warnings INTERFACE -fsanitize=address,undefined)
endif()

# icd_add_library(name SOURCES ... PUBLIC_LINK ... PRIVATE_LINK ...) creates
# icd_<name> with alias icd::<name>. A library module's headers are included
# as <icd/<module>/...> (the build tree maps generated/icd/<module> to the
# source folder, the install tree has include/icd/<module>). The application
# layer (experiments/, tests/) also includes "experiments/..." from the
# source root (directory-scoped there).
function(icd_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_LINK;PRIVATE_LINK" ${ARGN})
  add_library(icd_${name} STATIC ${ARG_SOURCES})
  add_library(icd::${name} ALIAS icd_${name})
  set_target_properties(icd_${name} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  target_include_directories(icd_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(icd_${name} PUBLIC cxx_std_20)
  target_link_libraries(icd_${name} PUBLIC ${ARG_PUBLIC_LINK} PRIVATE ${ARG_PRIVATE_LINK}
                        $<BUILD_INTERFACE:icd::warnings>)
endfunction()
