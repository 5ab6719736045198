// Input and environment errors: thrown as pvrr::Error with context, caught once in main (exit code 1).
// Broken invariants use PVRR_CHECK (an internal error, exit code 2).
#pragma once
#include <sstream>
#include <stdexcept>
#include <string>

namespace pvrr {

// An error in the user's input or environment. The message is complete and printed as is, e.g.
// "models/x.json: elements[1].material.n_d: expected a number > 1, got \"abc\"".
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A broken internal invariant (a bug). Carries file and line.
class InternalError : public std::logic_error {
 public:
  explicit InternalError(const std::string& message) : std::logic_error(message) {}
};

}  // namespace pvrr

#define PVRR_CHECK(cond, ...)                                                                   \
  do {                                                                                          \
    if (!(cond)) {                                                                              \
      std::ostringstream pvrr_check_os_;                                                        \
      pvrr_check_os_ << __FILE__ << ":" << __LINE__ << ": check failed: " #cond " " __VA_ARGS__; \
      throw ::pvrr::InternalError(pvrr_check_os_.str());                                        \
    }                                                                                           \
  } while (0)
