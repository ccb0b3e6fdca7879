// octray-bench: the octray command line with the bench's Embree baseline linked in.
// `octray bench` runs it with its own command line (tools/own_executable.h); it parses
// that as octray does and measures.

#include "tools/bench_arguments.h"
#include "tools/commands.h"
#include "tools/own_executable.h"

int main(int argc, char** argv) {
    using namespace octray::tools;
    OwnExecutable<BenchArguments>::set_body(&run_bench_command);
    return octray_main(argc, argv);
}
