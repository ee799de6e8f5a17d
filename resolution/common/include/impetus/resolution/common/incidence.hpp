#pragma once
/// \file
/// Which movable bodies a set of impulse rows joins, both ways: per row its bodies' slots (−1 for a fixed
/// body), per body slot its rows. Rebuilt in place (assign) from step to step, it allocates only when an
/// island is larger than any before it. The matrix of eq. 7 (A_ik ≠ 0 only where rows i and k share a movable
/// body), the paper mode's stale-row tracking, the complementary mode's start set and the sequential
/// resolver's refresh of v_n all read it.

#include "impetus/resolution/common/impulse_rows.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace impetus::resolution {

/// The row–body incidence of the rows `island` (indices into `rows`; local row i is rows[island[i]]).
/// Bodies are numbered by `slot_of_body` (per body index: its slot in 0 … movable − 1, or −1 for a fixed
/// body, which joins nothing). Built once per island, O(rows + movable).
struct Incidence {
  std::vector<std::array<std::int32_t, 2>> slots;  ///< per local row: the slots of its bodies a, b (−1: fixed)
  std::vector<std::uint32_t> body_start;           ///< per slot s: its rows are body_rows[body_start[s] …]
  std::vector<std::uint32_t> body_rows;            ///< local row indices, increasing per slot

  Incidence() = default;
  Incidence(std::span<const ImpulseRow> rows, std::span<const std::uint32_t> island, std::size_t movable,
            std::span<const std::int32_t> slot_of_body) {
    assign(rows, island, movable, slot_of_body);
  }
  /// Rebuilds the incidence for another island (the constructor's arguments), reusing the buffers.
  void assign(std::span<const ImpulseRow> rows, std::span<const std::uint32_t> island, std::size_t movable,
              std::span<const std::int32_t> slot_of_body);

  /// Whether row i's side k (0: a, 1: b) is a movable body not already listed for it as side 0 (a row
  /// joining a body to itself is listed once).
  bool listed(std::size_t i, std::size_t k) const {
    return slots[i][k] >= 0 && !(k == 1 && slots[i][0] == slots[i][1]);
  }
  /// The rows of body slot s (local indices, increasing); empty for s < 0 (a fixed body).
  std::span<const std::uint32_t> rows_of(std::int32_t s) const {
    if (s < 0) return {};
    return {body_rows.data() + body_start[static_cast<std::size_t>(s)],
            body_rows.data() + body_start[static_cast<std::size_t>(s) + 1]};
  }
  /// The rows of row i's side k if listed(i, k), else empty: the lists whose union is column i of A.
  std::span<const std::uint32_t> side_rows(std::size_t i, std::size_t k) const {
    return listed(i, k) ? rows_of(slots[i][k]) : std::span<const std::uint32_t>();
  }

 private:
  std::vector<std::uint32_t> cursor_;  // assign's scratch: per slot, where its next row goes
};

}  // namespace impetus::resolution
