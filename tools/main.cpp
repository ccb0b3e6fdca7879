// octray: the command line. Thin by design: parse, call the library, report
// (tools/octray_main.cpp). `octray view` runs the viewer's executable, octray-view
// (tools/view_launch.h), so that this one loads no HTTP or TLS library.

#include "tools/commands.h"

int main(int argc, char** argv) { return octray::tools::octray_main(argc, argv); }
