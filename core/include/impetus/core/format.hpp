#pragma once
/// \file
/// Text in messages and outputs. Numbers: the shortest text that reads back as exactly the same double
/// (std::to_chars), so 1e-7 prints as "1e-07", 0.0001234567 keeps every digit and 1e308 is not 309
/// digits long. Values that pass through text (a command-line flag turned into a scene override, a
/// CSV, module options) use it so they survive the round trip bit for bit.

#include <array>
#include <charconv>
#include <algorithm>
#include <string>
#include <string_view>

namespace impetus {

/// The shortest text that parses back to exactly `x` ("inf", "-inf" and "nan" for the non-finite).
inline std::string format_number(double x) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  return std::string(buffer.data(), result.ptr);
}

/// Whether `text` holds a control character (a line break, tab, NUL, escape …): such a name would cut a
/// message short or break a CSV row, so names are refused with one.
inline bool has_control_character(std::string_view text) {
  return std::any_of(text.begin(), text.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u < 0x20 || u == 0x7f;
  });
}

}  // namespace impetus
