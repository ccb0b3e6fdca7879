#!/usr/bin/env bash
# The README's test command, and all of CI (.ci/run calls exactly this), on a fresh
# Debian 12 with 2 cores:
#   1. install what is missing (tools/setup.sh, apt),
#   2. release preset (g++ 12, -Wall -Wextra -Werror, Embree): build, run the whole suite,
#      then install that build into a temporary prefix and build and run examples/embed
#      against the installed package (tests/install/run.sh), then the render-farm test:
#      a private single-node Slurm runs tools/farm/slurm_array.sh with one task killed
#      and requeued (tests/farm/slurm.sh, at most 600 s; it stops its daemons itself,
#      also when the timeout's SIGTERM ends it),
#   3. asan preset (clang, ASan + UBSan, Embree off so that configuration is built and
#      tested too): build, run the whole suite again plus every libFuzzer target for
#      OCTRAY_FUZZ_SECONDS (30) each,
#   4. ThreadSanitizer over the parallel rendering tests and a batch render, against a
#      oneTBB built with -fsanitize=thread from Debian's source (tests/tsan/run.sh).
# Quicker loop while developing: ctest --preset release (after a build).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
start=$SECONDS
tools/setup.sh

cmake --preset release
cmake --build --preset release -j2
ctest --preset release
echo "tools/test.sh: release done at $((SECONDS - start)) s"
tests/install/run.sh build/release
echo "tools/test.sh: install + examples/embed done at $((SECONDS - start)) s"
farm_start=$SECONDS
farm_status=0
timeout 600 tests/farm/slurm.sh build/release/tools/octray || farm_status=$?
echo "tools/test.sh: slurm farm test took $((SECONDS - farm_start)) s (exit $farm_status)," \
    "done at $((SECONDS - start)) s"
if [[ $farm_status -ne 0 ]]; then
    exit "$farm_status"
fi

cmake --preset asan
cmake --build --preset asan -j2
ctest --preset asan
echo "tools/test.sh: asan done at $((SECONDS - start)) s"

tests/tsan/run.sh
echo "tools/test.sh: passed in $((SECONDS - start)) s"
