# The accuracy scenarios as a static library, shared by bench_accuracy (benchmarks/accuracy/) and
# test_accuracy (tests/accuracy/). Included from both folders; the first inclusion defines it.
include_guard(GLOBAL)

set(_accuracy_dir "${CMAKE_CURRENT_LIST_DIR}")
add_library(impetus_accuracy STATIC
  ${_accuracy_dir}/scenarios.cpp ${_accuracy_dir}/probes.cpp ${_accuracy_dir}/runner.cpp ${_accuracy_dir}/report.cpp)
target_include_directories(impetus_accuracy PUBLIC ${_accuracy_dir})
target_link_libraries(impetus_accuracy PUBLIC impetus_engine nlohmann_json::nlohmann_json
                                       PRIVATE impetus_compile_options)
# Runs load these plugins by name at run time.
set(IMPETUS_ACCURACY_PLUGINS impetus_integrator_euler impetus_integrator_momentum impetus_integrator_splitting
    impetus_detector_fcl
    impetus_resolver_ledas impetus_resolver_mirtich)
foreach(plugin ${IMPETUS_ACCURACY_PLUGINS})
  if(TARGET ${plugin})
    add_dependencies(impetus_accuracy ${plugin})
  endif()
endforeach()
