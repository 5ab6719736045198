#include "app/cli.h"
#include <cstdio>
namespace pvrr::app {
int runMain(int, char**) { std::fprintf(stderr, "pvrr: not built yet\n"); return 2; }
}
