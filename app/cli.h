#pragma once
namespace pvrr::app {
// Runs the pvrr command line; returns the exit code (0 ok, 1 usage or input error, 2 internal error).
int runMain(int argc, char** argv);
}
