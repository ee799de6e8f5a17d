# impetus_add_plugin(<kind> <name> SOURCES <files...> [LIBRARIES <targets...>] [STAYS_LOADED])
#
# Declares a module plugin in one line. <kind> is integrator, detector or resolver; <name> is the name a
# scene uses. Builds the shared library impetus_<kind>_<name>.so (no "lib" prefix) into the plugin
# directory the host searches, with hidden visibility (only the entry symbol is exported), and installs
# it next to the core library. The target is named impetus_<kind>_<name>.
#
# STAYS_LOADED links the plugin with -z nodelete: dlclose then leaves it (and the libraries it pulled in)
# mapped until the process exits. A plugin needs it when it starts threads that outlive a call, such as
# oneTBB's worker pool: in a program that does not link that library itself (the plugin host alone, a
# conformance test), the last module's dlclose would otherwise unmap the library under its sleeping
# workers, and the process would crash later, at a time that depends on the scheduler.
include_guard(GLOBAL)

function(impetus_add_plugin kind name)
  cmake_parse_arguments(ARG "STAYS_LOADED" "" "SOURCES;LIBRARIES" ${ARGN})
  if(NOT kind MATCHES "^(integrator|detector|resolver)$")
    message(FATAL_ERROR "impetus_add_plugin: kind must be integrator, detector or resolver, got '${kind}'")
  endif()
  if(NOT name MATCHES "^[a-z][a-z0-9_]*$")
    message(FATAL_ERROR "impetus_add_plugin: name '${name}' must be lower-case letters, digits and _")
  endif()
  set(target impetus_${kind}_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE Impetus::plugin_api ${ARG_LIBRARIES})
  if(TARGET impetus_compile_options)
    target_link_libraries(${target} PRIVATE impetus_compile_options)
  endif()
  set_target_properties(${target} PROPERTIES
    PREFIX ""
    OUTPUT_NAME ${target}
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  # Hidden visibility does not cover instantiations of std:: templates (libstdc++ declares namespace std
  # visible), which would then be exported and could bind to the host's copies; a version script keeps
  # the entry symbol the only export.
  set(exports "${CMAKE_CURRENT_BINARY_DIR}/impetus_plugin.exports")
  file(CONFIGURE OUTPUT "${exports}" CONTENT "{ global: impetus_plugin_descriptor; local: *; };\n")
  target_link_options(${target} PRIVATE "LINKER:--version-script=${exports}")
  set_property(TARGET ${target} APPEND PROPERTY LINK_DEPENDS "${exports}")
  if(ARG_STAYS_LOADED)
    target_link_options(${target} PRIVATE "LINKER:-z,nodelete")
  endif()
  if(DEFINED IMPETUS_PLUGIN_OUTPUT_DIRECTORY)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY "${IMPETUS_PLUGIN_OUTPUT_DIRECTORY}")
  endif()
  if(DEFINED IMPETUS_PLUGIN_INSTALL_DIR)
    install(TARGETS ${target} LIBRARY DESTINATION "${IMPETUS_PLUGIN_INSTALL_DIR}")
  endif()
endfunction()

# impetus_add_module_library(<target> SOURCES <files...> [INCLUDE_DIR <dir>] [PUBLIC_LIBRARIES <...>]
#                            [PRIVATE_LIBRARIES <...>])
#
# The plain library behind a plugin ("the algorithm as a plain library that tests can call
# directly, plus a thin entry file"): STATIC, position-independent so it can go into the plugin's shared
# object, hidden visibility, built against Impetus::plugin_api (never the core library). INCLUDE_DIR
# (the plugin's include root, so headers read "impetus/integrators/euler/euler.hpp") is exported to its
# users.
function(impetus_add_module_library target)
  cmake_parse_arguments(ARG "" "INCLUDE_DIR" "SOURCES;PUBLIC_LIBRARIES;PRIVATE_LIBRARIES" ${ARGN})
  add_library(${target} STATIC ${ARG_SOURCES})
  if(ARG_INCLUDE_DIR)
    target_include_directories(${target} PUBLIC ${ARG_INCLUDE_DIR})
  endif()
  target_link_libraries(${target} PUBLIC Impetus::plugin_api Impetus::settings ${ARG_PUBLIC_LIBRARIES}
                                  PRIVATE ${ARG_PRIVATE_LIBRARIES})
  if(TARGET impetus_compile_options)
    target_link_libraries(${target} PRIVATE impetus_compile_options)
  endif()
  set_target_properties(${target} PROPERTIES
    POSITION_INDEPENDENT_CODE ON
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
endfunction()
