#pragma once
/// \file
/// Counts the program's calls of the global `operator new` (all its forms), for the `allocations`
/// counter of the step family: how many heap allocations one steady-state World::step() makes (issue:
/// no allocation in the steady state). Linked into `bench_step` only (allocation_counter.cpp replaces the
/// global operators for that program, plugins and libraries included). Memory taken by `malloc` directly
/// (Eigen's dynamic matrices, C libraries) is not counted.

#include <cstdint>

namespace impetus::bench {

/// operator new calls since the program started.
std::uint64_t allocations() noexcept;

}  // namespace impetus::bench
