#include "impetus/resolution/common/incidence.hpp"

namespace impetus::resolution {

void Incidence::assign(std::span<const ImpulseRow> rows, std::span<const std::uint32_t> island, std::size_t movable,
                       std::span<const std::int32_t> slot_of_body) {
  const std::size_t m = island.size();
  slots.resize(m);
  body_start.assign(movable + 1, 0);
  for (std::size_t i = 0; i < m; ++i) {  // count each body's rows, then lay them out in row order
    const ImpulseRow& r = rows[island[i]];
    slots[i] = {slot_of_body[r.a], slot_of_body[r.b]};
    for (std::size_t k = 0; k < 2; ++k)
      if (listed(i, k)) ++body_start[static_cast<std::size_t>(slots[i][k]) + 1];
  }
  for (std::size_t s = 0; s < movable; ++s) body_start[s + 1] += body_start[s];
  body_rows.resize(body_start.back());
  cursor_.assign(body_start.begin(), body_start.end() - 1);
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t k = 0; k < 2; ++k)
      if (listed(i, k)) body_rows[cursor_[static_cast<std::size_t>(slots[i][k])]++] = static_cast<std::uint32_t>(i);
}

}  // namespace impetus::resolution
