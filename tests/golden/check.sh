#!/usr/bin/env bash
# Golden-image regression: re-renders every scene in scenes/ with both render paths and
# compares each against its stored reference tests/golden/<name>.exr (see README.md).
#
#   check.sh OCTRAY                         compare (exit 0 when every image passes)
#   OCTRAY_UPDATE_GOLDEN=1 check.sh OCTRAY  re-render the references with the scalar path
#   check.sh --self-test OCTRAY             prove the comparison can fail: a render of
#                                           pinhole_checker with its light 1% dimmer must
#                                           be judged FAIL (compare exit 2)
#
# The threshold: the references are stored as half floats, whose rounding is at most
# 2^-11 (about 4.9e-4) relative; 0.002 absolute tolerates that for values up to 4 and
# still catches any real change of the image (see README.md).
set -euo pipefail

self_test=0
if [[ ${1:-} == --self-test ]]; then
    self_test=1
    shift
fi
if [[ $# -ne 1 ]]; then
    echo "usage: $0 [--self-test] path/to/octray" >&2
    exit 2
fi
octray=$1
here=$(cd "$(dirname "$0")" && pwd)
size=(--width 96 --height 64)
fail_threshold=0.002

scenes=("$here"/scenes/*.json)

# An animated scene is checked at one frame, named in its file name: name_f17.json is
# frame 17 (rendered alone, which equals frame 17 of the sequence).
frame_args() {
    local name=$1
    if [[ $name =~ _f([0-9]+)$ ]]; then
        echo "--frames ${BASH_REMATCH[1]}"
    fi
}
if [[ ${#scenes[@]} -eq 0 ]]; then
    echo "no scenes in $here/scenes" >&2
    exit 1
fi

if [[ ${OCTRAY_UPDATE_GOLDEN:-0} == 1 ]]; then
    for scene in "${scenes[@]}"; do
        name=$(basename "$scene" .json)
        # shellcheck disable=SC2046  # frame_args is one option and a number, or nothing
        "$octray" render "$scene" --path scalar "${size[@]}" $(frame_args "$name") \
            -o "$here/$name.exr" >/dev/null
        echo "rewrote $here/$name.exr ($(stat -c %s "$here/$name.exr") bytes)"
    done
    echo "review the new references (git diff --stat tests/golden) before committing them"
    exit 0
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# compare GOLDEN NEW: octray compare's exit status (0 pass, 1 warn, 2 fail, 3, 4), its
# report in $tmp/compare.log. --warn keeps its default (1e-6), so any difference at all
# shows up as WARN without failing the check.
compare() {
    local status=0
    "$octray" compare "$1" "$2" --fail "$fail_threshold" --failpercent 0 \
        >"$tmp/compare.log" 2>&1 || status=$?
    return "$status"
}

if [[ $self_test == 1 ]]; then
    scene=$here/scenes/pinhole_checker.json
    # The same scene with its one light at 0.891 instead of 0.9.
    sed 's/"type": "point", "position": \[-3, 6, 4\], "color": 0.9}/"type": "point", "position": [-3, 6, 4], "color": 0.891}/' \
        "$scene" >"$tmp/altered.json"
    if cmp -s "$scene" "$tmp/altered.json"; then
        echo "self-test: could not alter $scene (did its light change?)" >&2
        exit 1
    fi
    "$octray" render "$tmp/altered.json" --path scalar "${size[@]}" -o "$tmp/altered.exr" >/dev/null
    status=0
    compare "$here/pinhole_checker.exr" "$tmp/altered.exr" || status=$?
    cat "$tmp/compare.log"
    if [[ $status -ne 2 ]]; then
        echo "self-test: a 1% dimmer light gave compare exit $status, expected 2 (FAIL)" >&2
        exit 1
    fi
    echo "self-test: a 1% dimmer light is caught (compare exit 2)"
    exit 0
fi
failures=0
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .json)
    golden=$here/$name.exr
    if [[ ! -f $golden ]]; then
        echo "FAIL $name: no reference $golden (create it with OCTRAY_UPDATE_GOLDEN=1)"
        failures=$((failures + 1))
        continue
    fi
    for path in scalar simd; do
        out=$tmp/$name-$path.exr
        # shellcheck disable=SC2046  # frame_args is one option and a number, or nothing
        if ! "$octray" render "$scene" --path "$path" "${size[@]}" $(frame_args "$name") \
            -o "$out" >"$tmp/render.log" 2>&1; then
            echo "FAIL $name ($path): render failed"
            cat "$tmp/render.log"
            failures=$((failures + 1))
            continue
        fi
        status=0
        compare "$golden" "$out" || status=$?
        if [[ $status -le 1 ]]; then
            echo "ok   $name ($path): $(tail -n 1 "$tmp/compare.log")"
        else
            echo "FAIL $name ($path): octray compare exited $status"
            cat "$tmp/compare.log"
            failures=$((failures + 1))
        fi
    done
done
if [[ $failures -ne 0 ]]; then
    echo "$failures comparison(s) failed; if the change is intended, regenerate with"
    echo "  OCTRAY_UPDATE_GOLDEN=1 $0 $octray"
    exit 1
fi
echo "all ${#scenes[@]} golden scenes match with both render paths"
