#!/usr/bin/env bash
# CI stage (tools/test.sh, after the release stage): install a build into a temporary
# prefix, check its man pages and shell completions, build examples/embed against the
# installed package alone, run it, and check its EXR: readable, and equal to what the
# installed `octray` renders from the same scene; then build it again with the compiler
# alone and the installed pkg-config file (octray.pc).
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

# The man pages and the shell completions (generated at build time from the parser's
# options): a page per command the installed octray lists, and both scripts, non-empty.
prefix=$tmp/prefix
commands=$("$prefix/bin/octray" --help | sed -n '/^Subcommands:/,/^$/p' | awk 'NR > 1 && NF { print $1 }')
test -n "$commands"
test -s "$prefix/share/man/man1/octray.1"
for command in $commands; do
  test -s "$prefix/share/man/man1/octray-$command.1" || {
    echo "tests/install/run.sh: no man page octray-$command.1 installed" >&2; exit 1; }
done
test "$(find "$prefix/share/man/man1" -type f | wc -l)" -eq $(($(wc -w <<<"$commands") + 1))
if command -v man >/dev/null; then
  man -M "$prefix/share/man" -w octray-render | grep -qx "$prefix/share/man/man1/octray-render.1"
fi
test -s "$prefix/share/bash-completion/completions/octray"
test -s "$prefix/share/zsh/vendor-completions/_octray"
grep -q '^#compdef octray' "$prefix/share/zsh/vendor-completions/_octray"
# The installed bash completion completes a command and an option.
completed=$(bash -c 'source "$1" && COMP_WORDS=(octray ma) COMP_CWORD=1 && _octray &&
  echo "${COMPREPLY[*]}" && COMP_WORDS=(octray render --thr) COMP_CWORD=2 && _octray &&
  echo "${COMPREPLY[*]}"' _ "$prefix/share/bash-completion/completions/octray")
test "$completed" = $'man\n--threads'

# `octray view` and `octray bench` run the executables installed in libexec/octray
# (tools/own_executable.h).
test -x "$prefix/libexec/octray/octray-view"
test -x "$prefix/libexec/octray/octray-bench"
"$prefix/bin/octray" view whitted --width 32 --height 18 --threads 1 --bench 2 |
  grep -q '^first picture: 32x18'
"$prefix/bin/octray" bench random:4 --rays primary --threads 1 --reps 1 --warmup 0 \
  --min-time 0 --width 16 --height 8 --no-embree 2>/dev/null | grep -q '^random:4 '

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

# The same example built without CMake, through the installed octray.pc; it renders the
# same image.
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
test "$(pkg-config --modversion octray)" = "$("$prefix/bin/octray" --version | awk '{print $2}')"
# shellcheck disable=SC2046  # pkg-config's flags are words
c++ -std=c++20 -Wall -Wextra -Werror -O2 examples/embed/main.cpp -o "$tmp/embed-pc" \
  $(pkg-config --cflags --libs octray)
"$tmp/embed-pc" "$tmp/embed-pc.exr"
"$prefix/bin/octray" compare "$tmp/embed.exr" "$tmp/embed-pc.exr"
echo "tests/install/run.sh: passed"
