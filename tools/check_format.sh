#!/usr/bin/env bash
# Fails when a tracked C++ file differs from what clang-format (the root .clang-format)
# would make of it, and names the files. Run by ctest (the clang_format test) in every
# preset; fix with: git ls-files '*.cpp' '*.h' | xargs clang-format -i
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
if ! command -v clang-format >/dev/null 2>&1; then
    echo "check_format: clang-format is not installed (tools/setup.sh installs it)" >&2
    exit 1
fi
mapfile -t files < <(git ls-files '*.cpp' '*.h')
if ((${#files[@]} == 0)); then
    echo "check_format: no tracked C++ files found (not a git checkout?)" >&2
    exit 1
fi
bad=()
for f in "${files[@]}"; do
    clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if ((${#bad[@]} > 0)); then
    echo "check_format: ${#bad[@]} of ${#files[@]} files are not clang-formatted:" >&2
    printf '  %s\n' "${bad[@]}" >&2
    echo "fix: git ls-files '*.cpp' '*.h' | xargs clang-format -i" >&2
    exit 1
fi
echo "check_format: all ${#files[@]} tracked C++ files are clang-formatted"
