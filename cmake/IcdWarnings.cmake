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

# Helper: add_icd_library(name SOURCES ...) creates icd_<name> with alias icd::<name>.
function(icd_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_LINK;PRIVATE_LINK" ${ARGN})
  add_library(icd_${name} STATIC ${ARG_SOURCES})
  add_library(icd::${name} ALIAS icd_${name})
  target_include_directories(icd_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated>)
  target_link_libraries(icd_${name} PUBLIC ${ARG_PUBLIC_LINK} PRIVATE icd::warnings ${ARG_PRIVATE_LINK})
  set_target_properties(icd_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
