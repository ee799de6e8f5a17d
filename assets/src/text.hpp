#pragma once
// Small text helpers shared by the mesh import sources (internal).

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>

namespace impetus::assets::detail {

inline std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

/// `x` with up to six significant digits ("%g").
inline std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

}  // namespace impetus::assets::detail
