#!/usr/bin/env bash
# Configures the `fuzz` preset (clang, libFuzzer, ASan + UBSan), builds the fuzzers and
# runs each one for OCTRAY_FUZZ_SECONDS (default 30) on its checked-in corpus, two at a
# time. Extra arguments go to the configure step, e.g.
#   tests/fuzz/run.sh -DOCTRAY_FUZZ_SECONDS=300
# A crash fails the run; libFuzzer prints the reproducer's path under
# build/fuzz/tests/fuzz/work/<fuzzer>/artifacts/ (tests/fuzz/README.md: what to do next).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

start=$SECONDS
cmake --preset fuzz "$@"
cmake --build --preset fuzz -j2
ctest --preset fuzz --no-tests=error -j2
echo "tests/fuzz/run.sh: passed in $((SECONDS - start)) s"
