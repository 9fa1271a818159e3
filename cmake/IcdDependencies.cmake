# Third-party dependencies, all from Debian packages (see scripts/install_deps.sh).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Threads REQUIRED)
find_package(CHOLMOD REQUIRED)   # cmake/FindCHOLMOD.cmake (SuiteSparse 5.12 ships no config)
find_package(METIS REQUIRED)     # cmake/FindMETIS.cmake

if(ICD_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(ICD_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
