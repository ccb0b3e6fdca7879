// octray: the command line. Thin by design: parse, call the library, report
// (tools/octray_main.cpp). `octray view` and `octray bench` run executables of their own,
// octray-view and octray-bench (tools/own_executable.h), so that this one loads no HTTP or
// TLS library and no Embree.

#include "tools/commands.h"

int main(int argc, char** argv) { return octray::tools::octray_main(argc, argv); }
