#!/usr/bin/env bash
# ThreadSanitizer over the parallel rendering tests (the reference's and the packet
# renderer's bit-identity across thread counts and tile sizes):
#   1. builds oneTBB with -fsanitize=thread once (tests/tsan/build_tbb.sh says why),
#   2. checks that TSan reports a planted race (tests/tsan/race_canary.cpp),
#   3. configures the `tsan` preset against that TBB, builds the test binaries and runs
#      their thread tests (both renderers, the parallel BVH build, BVH renders) with
#      halt_on_error=1 and tests/tsan/tsan.supp,
#   4. renders a small batch with `octray render` (progress thread, progressive passes),
#   5. and one whose frames are written while the next renders (write behind).
# Usage: tests/tsan/run.sh   (root on a fresh machine: step 1 adds a deb-src entry)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

start=$SECONDS
tests/tsan/build_tbb.sh
tbb=$PWD/build/tsan-tbb/install

# 2. The canary must be caught.
mkdir -p build/tsan
c++ -std=c++20 -g -O1 -fsanitize=thread tests/tsan/race_canary.cpp -o build/tsan/race_canary
if TSAN_OPTIONS=halt_on_error=1 build/tsan/race_canary > build/tsan/race_canary.log 2>&1 ||
   ! grep -q "ThreadSanitizer: data race" build/tsan/race_canary.log; then
  cat build/tsan/race_canary.log
  echo "tests/tsan/run.sh: ThreadSanitizer missed the planted race; the setup is broken" >&2
  exit 1
fi

# 3. The thread tests. The test preset sets TSAN_OPTIONS (suppressions, halt_on_error=1).
cmake --preset tsan  # TBB_DIR: build/tsan-tbb/install (the preset)
cmake --build --preset tsan -j2
ctest --preset tsan --no-tests=error \
  -R 'ReferenceRender\.ThreadCountAndTileSizeDoNotChangeASingleBit|PacketRenderer\.BitIdenticalForAnyThreadCountAndTileSize|SphereBvh\.DeterministicAcrossThreadCounts|BvhRender\.BuiltinScenesMatchTheReference'

# 4. A batch render: two render threads, the progress ticker thread reading the pixel
#    counter the tiles advance, a BVH built in parallel, progressive passes.
export TSAN_OPTIONS="suppressions=$PWD/tests/tsan/tsan.supp halt_on_error=1 second_deadlock_stack=1"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
build/tsan/tools/octray render random:64,width=96,height=64,spp=4 --frames 0-3 --threads 2 \
  --progress lines --progressive -o "$out/t.#.exr" > build/tsan/batch_render.log 2>&1 ||
  { cat build/tsan/batch_render.log; echo "tests/tsan/run.sh: the batch render failed" >&2; exit 1; }
# 5. Frames written behind: each frame's EXR and PNG written by a thread of its own (and
#    OpenEXR's pool) while the next frame renders on the TBB workers.
build/tsan/tools/octray render random:64,width=96,height=64 --frames 0-3 --threads 2 \
  --progress lines --png "$out/w.#.png" -o "$out/w.#.exr" > build/tsan/write_behind.log 2>&1 ||
  { cat build/tsan/write_behind.log; echo "tests/tsan/run.sh: the write-behind render failed" >&2; exit 1; }
echo "tests/tsan/run.sh: passed in $((SECONDS - start)) s"
