#pragma once
// Number formatting for the eval module's error messages.
#include <cstdio>
#include <string>

namespace drover::eval {

// Short human form of a number ("1.5", "100", "40.1434"), as printf's %g.
inline std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

}  // namespace drover::eval
