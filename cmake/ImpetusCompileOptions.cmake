# Compiler settings shared by every Impetus target (and by installed plugin projects).
include_guard(GLOBAL)

# impetus_warning_options: the language level, warnings and floating-point settings alone, for a program
# that must not be sanitized (the mesh importer: AddressSanitizer's shadow memory defeats RLIMIT_AS).
# impetus_compile_options: those plus the sanitizers when IMPETUS_SANITIZE is on.
add_library(impetus_warning_options INTERFACE)
add_library(impetus_compile_options INTERFACE)
target_link_libraries(impetus_compile_options INTERFACE impetus_warning_options)
target_compile_features(impetus_warning_options INTERFACE cxx_std_20)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  # -ffp-contract=off: no fused multiply-add contraction, so results do not depend on it (determinism).
  target_compile_options(impetus_warning_options INTERFACE
    $<BUILD_INTERFACE:-Wall -Wextra -Wpedantic -ffp-contract=off>)
  if(IMPETUS_WERROR)
    target_compile_options(impetus_warning_options INTERFACE $<BUILD_INTERFACE:-Werror>)
  endif()
  if(IMPETUS_SANITIZE)
    # -O1 -g1 (after the build type's flags, so they win): the sanitizers' usual level, with line tables
    # for the reports' stacks but no variable info. The heaviest file builds in 0.6x the time it takes
    # at -O2 -g, which keeps the test command's second pass short.
    target_compile_options(impetus_compile_options INTERFACE
      $<BUILD_INTERFACE:-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
                        -O1 -g1>)
    target_link_options(impetus_compile_options INTERFACE
      $<BUILD_INTERFACE:-fsanitize=address,undefined>)
  endif()
endif()
