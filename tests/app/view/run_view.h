// Running `pvrr view` in a window for the window tests (label `window`): under xvfb-run where it is installed,
// else on $DISPLAY; a test is skipped, saying why, only where no X server can be started.
#pragma once
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "app/run_pvrr.h"

namespace pvrr::test {

// Runs `pvrr view ARGS` with an X display: under xvfb-run where it is installed, else on $DISPLAY. Sets `why`
// and returns false when neither can start an X server.
inline bool runView(const std::string& args, CliResult* r, std::string* why) {
  const bool xvfb = std::system("command -v xvfb-run >/dev/null 2>&1") == 0;
  const char* display = std::getenv("DISPLAY");
  if (!xvfb && !(display && *display)) {
    *why = "no X server: xvfb-run is not installed (scripts/setup installs it) and DISPLAY is not set";
    return false;
  }
  if (!xvfb) {
    *r = runPvrr("view " + args);
    return true;
  }
  // Parallel tests may race for a display number (xvfb-run -a): a few tries before giving up.
  for (int attempt = 0; attempt < 3; ++attempt) {  // the virtual screen is larger than any window the tests open
    *r = runCaptured("cd '" PVRR_SOURCE_DIR "' && xvfb-run -a -s '-screen 0 1600x1000x24' '" PVRR_BINARY "' view " +
                     args);
    if (r->err.find("Xvfb failed to start") == std::string::npos) return true;
  }
  *why = "xvfb-run could not start Xvfb (3 tries): " + r->err;
  return false;
}

inline void writeText(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

#define RUN_VIEW_OR_SKIP(args, result)                       \
  do {                                                       \
    std::string why_;                                        \
    if (!runView(args, result, &why_)) GTEST_SKIP() << why_; \
  } while (0)

}  // namespace pvrr::test
