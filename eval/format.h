#pragma once
// Number formatting shared by the eval tables.

#include <cstdio>
#include <string>

namespace rovo {

// printf-style formatting of one number, e.g. Fmt("%.3f", x).
inline std::string Fmt(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

}  // namespace rovo
