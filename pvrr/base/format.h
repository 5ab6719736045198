// Numbers in notes and messages.
#pragma once
#include <cstdio>
#include <string>

namespace pvrr {

// x printed with a printf format for one double ("%.3g", "%.3f").
inline std::string fmt(const char* format, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

// Appends `part` to a note of parts separated by "; " (nothing for an empty part).
inline void appendNote(std::string& note, const std::string& part) {
  if (!part.empty()) note += (note.empty() ? "" : "; ") + part;
}

}  // namespace pvrr
