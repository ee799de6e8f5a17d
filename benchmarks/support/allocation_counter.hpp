#pragma once
/// \file
/// Counts the program's heap allocations: calls of the global `operator new` (all its forms) and of C's
/// `malloc`, `calloc` and `realloc` (Eigen's dynamic matrices, C libraries), for the `allocations`
/// counter of the step family and the steady-state test (tests/reliability/steady_state_test.cpp): how
/// many allocations one steady-state World::step() makes. Linked into `bench_step` and that test only
/// (allocation_counter.cpp replaces the functions for the program, plugins and libraries included).
/// Under AddressSanitizer only `operator new` is counted (the sanitizer owns malloc).

#include <cstdint>

namespace impetus::bench {

/// Allocations since the program started.
std::uint64_t allocations() noexcept;
/// Whether malloc, calloc and realloc are counted too (not under AddressSanitizer).
bool counts_malloc() noexcept;

}  // namespace impetus::bench
