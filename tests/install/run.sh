#!/usr/bin/env bash
# CI stage (tools/test.sh, after the release stage): install a build into a temporary
# prefix, build examples/embed against the installed package alone, run it, and check its
# EXR: readable, and equal to what the installed `octray` renders from the same scene.
#   tests/install/run.sh [BUILD_DIR]     (default build/release, already built)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
build=${1:-build/release}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

cmake --install "$build" --prefix "$tmp/prefix"
# Only the public header is installed.
test -f "$tmp/prefix/include/octray/octray.h"
test "$(find "$tmp/prefix/include" -type f | wc -l)" -eq 1

cmake -S examples/embed -B "$tmp/embed" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$tmp/prefix"
cmake --build "$tmp/embed" -j2
"$tmp/embed/embed" "$tmp/embed.exr" "$tmp/embed.json"

# The EXR exists and reads back; the installed CLI renders the scene the example wrote to
# the same pixels.
test -s "$tmp/embed.exr"
"$tmp/prefix/bin/octray" render "$tmp/embed.json" --float --threads 2 -o "$tmp/cli.exr" \
  --progress none
"$tmp/prefix/bin/octray" compare "$tmp/embed.exr" "$tmp/cli.exr"
echo "tests/install/run.sh: passed"
