#!/usr/bin/env bash
# The README's test command: install what is missing, build the release preset and run
# the whole suite. .ci/run calls exactly this, then the same under ASan + UBSan.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
tools/setup.sh
cmake --preset release
cmake --build --preset release -j2
ctest --preset release
