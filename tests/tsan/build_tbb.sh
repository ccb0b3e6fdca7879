#!/usr/bin/env bash
# Builds oneTBB with -fsanitize=thread into build/tsan-tbb/install, from the Debian
# source package of the libtbb-dev that is installed (same version as the system
# headers). Why: ThreadSanitizer only sees synchronisation in instrumented code, and
# Debian's libtbb.so is not instrumented, so every task hand-off and every join inside
# parallel_for looks like a race (276 reports on the two thread tests, all in TBB's task
# machinery or on data handed over by it). With an instrumented TBB there are none, and
# tests/tsan/tsan.supp stays empty. Needs root (or sudo) for the deb-src entry on a fresh
# machine; skips everything when the install already exists.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
root=$PWD/build/tsan-tbb
if [[ -f $root/install/lib/cmake/TBB/TBBConfig.cmake ]]; then exit 0; fi

mkdir -p "$root/src"
version=$(dpkg-query -W -f='${source:Version}' libtbb-dev)
if ! ls "$root"/src/onetbb_*.orig.tar.* > /dev/null 2>&1; then
  # Source indices for the suites already configured, in a file of our own, removed on exit.
  as_root=()
  if [[ "$(id -u)" -ne 0 ]]; then as_root=(sudo); fi
  list=/etc/apt/sources.list.d/octray-tsan-deb-src.sources
  sed -n '/^Types: deb$/,/^$/p' /etc/apt/sources.list.d/debian.sources |
    sed 's/^Types: deb$/Types: deb-src/' | "${as_root[@]}" tee "$list" > /dev/null
  trap '"${as_root[@]}" rm -f "$list"' EXIT
  "${as_root[@]}" apt-get update -qq
  (cd "$root/src" && apt-get source --download-only -qq "onetbb=$version")
fi
tar -xf "$root"/src/onetbb_*.orig.tar.* -C "$root/src"
cmake -S "$root"/src/oneTBB-* -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DTBB_SANITIZE=thread -DTBB_TEST=OFF -DTBB_EXAMPLES=OFF -DTBBMALLOC_BUILD=OFF \
  -DTBB_STRICT=OFF -DCMAKE_INSTALL_PREFIX="$root/install"
cmake --build "$root/build" -j2
cmake --install "$root/build"
