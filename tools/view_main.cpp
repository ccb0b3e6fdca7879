// octray-view: the octray command line with the live viewer linked in (view/: the HTTP
// server, its TLS-capable library, JPEG). `octray view` runs it with its own command line
// (tools/own_executable.h); it parses that as octray does and serves.

#include "tools/commands.h"
#include "tools/own_executable.h"
#include "tools/view_arguments.h"

int main(int argc, char** argv) {
    using namespace octray::tools;
    OwnExecutable<ViewArguments>::set_body(&run_view);
    return octray_main(argc, argv);
}
