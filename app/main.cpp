#include "app/cli.h"
int main(int argc, char** argv) { return pvrr::app::runMain(argc, argv); }
