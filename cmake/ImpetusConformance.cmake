# impetus_add_conformance_tests(<target> KIND <integrator|detector|resolver> PLUGIN <plugin target or .so path>
#                               [LABEL <name>] [OPTIONS <key=value>...] [CLAIMS <capability>...]
#                               [APPROACH_TOLERANCE <m/s>])
#
# Builds the GoogleTest executable <target> that runs the conformance suite of KIND (the contract's
# closed forms, conservation laws, refusals and determinism; plugins/conformance/) on one plugin, loaded
# from its shared library through the plugin host as a scene would load it, and registers its tests
# with CTest. The same function serves Impetus's own plugins and a plugin built outside Impetus against
# an installed Impetus (plugins/template/CMakeLists.txt).
#   LABEL               test-name suffix (default: the plugin's name); letters, digits and _
#   OPTIONS             options every module is created with, as a scene would write them (mode=paper)
#   CLAIMS              capabilities beyond the contract that the plugin documents, each enabling a test:
#                       integrator `angular_momentum` (L conserved without torque), resolver `elastic`
#                       (kinetic energy conserved when every e = 1), detector `margin`
#                       (reads the option `margin`; gaps within it are contacts of depth −gap)
#   APPROACH_TOLERANCE  resolvers: the largest v_n < 0 (m/s) left at a contact, default 1e-6
# Needs GoogleTest (find_package(GTest)) and the variable IMPETUS_CONFORMANCE_DIR (set by Impetus's
# package config, and by Impetus's own build).
include_guard(GLOBAL)
include(GoogleTest)

# The library that provides the plugin host (impetus/plugins/host.hpp) to the suites: the only link.
set(IMPETUS_CONFORMANCE_HOST_TARGET Impetus::plugin_host)

# The objects of one kind's suite (and the shared support), compiled once per project and shared by
# every executable that tests a plugin of that kind. Only the kinds asked for are built.
function(_impetus_conformance_objects kind)
  if(NOT TARGET GTest::gtest)
    find_package(GTest REQUIRED)
  endif()
  set(created "")
  if(NOT TARGET impetus_conformance_support)
    add_library(impetus_conformance_support OBJECT "${IMPETUS_CONFORMANCE_DIR}/src/support.cpp")
    list(APPEND created impetus_conformance_support)
  endif()
  if(NOT TARGET impetus_conformance_${kind})
    add_library(impetus_conformance_${kind} OBJECT "${IMPETUS_CONFORMANCE_DIR}/src/${kind}_suite.cpp")
    list(APPEND created impetus_conformance_${kind})
  endif()
  foreach(objects IN LISTS created)
    target_include_directories(${objects} PUBLIC "${IMPETUS_CONFORMANCE_DIR}/include")
    target_link_libraries(${objects} PUBLIC ${IMPETUS_CONFORMANCE_HOST_TARGET} GTest::gtest)
    target_compile_features(${objects} PUBLIC cxx_std_20)
    if(TARGET impetus_compile_options)
      target_link_libraries(${objects} PRIVATE impetus_compile_options)
    endif()
  endforeach()
endfunction()

function(impetus_add_conformance_tests target)
  cmake_parse_arguments(ARG "" "KIND;PLUGIN;LABEL;APPROACH_TOLERANCE" "OPTIONS;CLAIMS" ${ARGN})
  if(NOT ARG_KIND MATCHES "^(integrator|detector|resolver)$")
    message(FATAL_ERROR "impetus_add_conformance_tests: KIND must be integrator, detector or resolver, got '${ARG_KIND}'")
  endif()
  if(NOT ARG_PLUGIN)
    message(FATAL_ERROR "impetus_add_conformance_tests: PLUGIN (a plugin target or a .so file) is required")
  endif()
  if(NOT DEFINED IMPETUS_CONFORMANCE_DIR OR NOT EXISTS "${IMPETUS_CONFORMANCE_DIR}/src/support.cpp")
    message(FATAL_ERROR "impetus_add_conformance_tests: IMPETUS_CONFORMANCE_DIR ('${IMPETUS_CONFORMANCE_DIR}') "
                        "does not hold the conformance suites; find_package(Impetus) sets it")
  endif()
  if(TARGET ${ARG_PLUGIN})
    set(file "$<TARGET_FILE:${ARG_PLUGIN}>")
    get_target_property(name ${ARG_PLUGIN} OUTPUT_NAME)
    if(NOT name)
      set(name ${ARG_PLUGIN})
    endif()
  else()
    set(file "${ARG_PLUGIN}")
    get_filename_component(name "${ARG_PLUGIN}" NAME_WE)
  endif()
  string(REGEX REPLACE "^impetus_${ARG_KIND}_" "" name "${name}")
  set(label "${name}")
  if(ARG_LABEL)
    set(label "${ARG_LABEL}")
  endif()
  if(NOT label MATCHES "^[A-Za-z0-9_]+$")
    message(FATAL_ERROR "impetus_add_conformance_tests: LABEL '${label}' must be letters, digits and _")
  endif()
  set(options "")
  foreach(option IN LISTS ARG_OPTIONS)
    if(NOT option MATCHES "^([A-Za-z0-9_]+)=(.*)$")
      message(FATAL_ERROR "impetus_add_conformance_tests: OPTIONS entry '${option}' is not key=value")
    endif()
    string(APPEND options "{\"${CMAKE_MATCH_1}\", \"${CMAKE_MATCH_2}\"}, ")
  endforeach()
  set(claims "")
  foreach(claim IN LISTS ARG_CLAIMS)
    string(APPEND claims "\"${claim}\", ")
  endforeach()
  set(tolerance 1e-6)
  if(ARG_APPROACH_TOLERANCE)
    set(tolerance ${ARG_APPROACH_TOLERANCE})
  endif()
  string(SUBSTRING ${ARG_KIND} 0 1 first)
  string(TOUPPER ${first} first)
  string(SUBSTRING ${ARG_KIND} 1 -1 rest)
  set(suite "${first}${rest}Conformance")

  _impetus_conformance_objects(${ARG_KIND})
  set(source "${CMAKE_CURRENT_BINARY_DIR}/${target}_instantiation.cpp")
  file(GENERATE OUTPUT "${source}" CONTENT
"// Generated by impetus_add_conformance_tests(${target}): the ${ARG_KIND} conformance suite for one plugin.
#include \"impetus/conformance/conformance.hpp\"

namespace impetus::conformance {
INSTANTIATE_TEST_SUITE_P(Plugin, ${suite},
                         ::testing::Values(PluginUnderTest{\"${label}\", \"${file}\", {${options}}, {${claims}}, ${tolerance}}),
                         plugin_label);
}  // namespace impetus::conformance
")
  add_executable(${target} "${source}")
  target_link_libraries(${target} PRIVATE impetus_conformance_support impetus_conformance_${ARG_KIND}
                                          GTest::gtest_main)
  if(TARGET ${ARG_PLUGIN})
    add_dependencies(${target} ${ARG_PLUGIN})
  endif()
  gtest_discover_tests(${target} DISCOVERY_TIMEOUT 60 NO_PRETTY_VALUES PROPERTIES ENVIRONMENT "IMPETUS_PLUGIN_PATH=")
endfunction()
