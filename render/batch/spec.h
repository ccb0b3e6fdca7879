#pragma once
// The specifications of a batch render (`octray render --frames ... -o pattern --shard
// ... --crop ...`): frame lists, output file patterns, shards of a frame list and crop
// rectangles. Pure functions of their arguments (shard_from_environment reads the
// environment only through the function it is given); every bad input is a SpecError
// whose message quotes the text (control bytes as \xNN, cut after 64 characters) and says
// what was expected. This header is the reference for the grammar and limits; the user's
// view is tools/README.md ("Batch rendering").

#include <cstddef>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/pixel_rect.h"

namespace octray::batch {

struct SpecError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// At most this many frames in one frame spec, repeats counted.
inline constexpr long long kMaxFrameSpecFrames = 1'000'000;

// "5", "0-47", "1-100:2", "1-100:2,150": comma-separated items, each a frame N, a range
// N-M (N <= M, both included) or a range with a step N-M:S (N, N+S, ... <= M; S >= 1).
// Numbers are decimal digits, 0 ... 2^31 - 1; blanks around numbers are ignored. Frames
// come back in the order written with repeats removed (the first occurrence kept).
// Refused: an empty spec or item ("1,,2", "1,"), a sign ("-3", "+3"), anything but digits
// ("1.5", "a-b", "0x10"), a missing bound ("5-", "1-10:"), a backwards range ("10-1"),
// a step of 0 or without a range ("5:2"), a number above 2^31 - 1, and more than
// kMaxFrameSpecFrames frames in all (counted before repeats are removed, so the work is
// bounded before any frame is listed).
std::vector<int> parse_frame_spec(std::string_view spec);

// True if the pattern has a frame field ('#' run, {frame} or {frame:0Nd}), so that every
// frame gets its own file. Throws SpecError for a malformed pattern (as expand does).
bool pattern_has_frame_field(std::string_view pattern);

// The pattern with its fields replaced: a run of N '#' is the frame zero-padded to N digits
// (more when the frame needs them), {frame} the frame, {frame:0Nd} (N = 1 ... 9) the frame
// zero-padded to N digits, {scene} `scene_name`; "{{" and "}}" are literal braces. Any
// other text in braces ({fram}, {frame:4d}, {frame:010d}), an unclosed '{' or a lone '}'
// is a SpecError. There is no escape for '#': every '#' is part of a frame field.
// `frame` must be >= 0.
std::string expand_output_pattern(std::string_view pattern, int frame,
                                  std::string_view scene_name);

// Shard `index` of `count` (0 <= index < count) renders the frames at positions k of the
// frame list with k % count == index.
struct Shard {
    int index = 0;
    int count = 1;
};

// "i/n": shard i of n, 0 <= i < n.
Shard parse_shard(std::string_view text);

// The shard of an array job (`--shard auto`), from the environment as `getenv_fn` sees it
// (pass std::getenv; tests pass a map). Empty variables count as unset.
//  - Slurm job arrays: SLURM_ARRAY_TASK_ID; index = (ID - SLURM_ARRAY_TASK_MIN) /
//    SLURM_ARRAY_TASK_STEP (MIN 0 and STEP 1 when unset); count = SLURM_ARRAY_TASK_COUNT,
//    or `shard_count` when that is unset (both given must agree).
//  - Kubernetes Indexed Jobs: JOB_COMPLETION_INDEX is the index; `shard_count` is required
//    (the Job's completions), since Kubernetes does not export it.
// SpecError when neither is set, a value is not a number, or the index is not below the
// count.
Shard shard_from_environment(const std::function<const char*(const char*)>& getenv_fn,
                             std::optional<int> shard_count);

// SpecError unless 0 <= shard.index < shard.count.
void check_shard(Shard shard);

// The items (frames, or the jobs of a run) at positions k with k % shard.count ==
// shard.index, in order. The shards 0 ... count - 1 of one list are disjoint and together
// hold every item once. SpecError for a bad shard (check_shard).
template <class T>
std::vector<T> select_shard(const std::vector<T>& items, Shard shard) {
    check_shard(shard);
    std::vector<T> out;
    for (std::size_t k = static_cast<std::size_t>(shard.index); k < items.size();
         k += static_cast<std::size_t>(shard.count))
        out.push_back(items[k]);
    return out;
}

// "x0,y0,x1,y1" with 0 <= x0 < x1 <= image_width and 0 <= y0 < y1 <= image_height.
PixelRect parse_crop(std::string_view text, int image_width, int image_height);

// The name of a scene for {scene} and default output names: the built-in's name with ':'
// turned into '-' and options dropped ("random:8,width=32" -> "random-8"), or a file's
// stem ("scenes/room.json" -> "room"); characters other than letters, digits, '-', '_'
// and '.' become '_'; "render" when nothing is left.
std::string scene_display_name(std::string_view scene_spec);

}  // namespace octray::batch
