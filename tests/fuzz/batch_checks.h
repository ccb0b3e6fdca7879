#pragma once
// The invariants of the batch-specification fuzzers (fuzz_frame_spec, fuzz_crop_spec) on
// render/batch/spec.h, one function per target. tests/batch/spec_test.cpp replays the
// checked-in corpus through the same functions, so a kept input stays a test in every
// build. Refusing input with SpecError is success; a broken invariant throws
// BatchInvariantBroken (std::terminate in a fuzzer, a failure in a GoogleTest).

#include <algorithm>
#include <climits>
#include <cstddef>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "render/batch/spec.h"

namespace octray::fuzz {

class BatchInvariantBroken : public std::logic_error {
  public:
    BatchInvariantBroken(const std::string& invariant, std::string_view input)
        : std::logic_error("invariant broken: " + invariant + " (input of " +
                           std::to_string(input.size()) + " bytes)") {}
};

// The input as a frame spec, and as an output pattern.
//  - parse_frame_spec: SpecError, or a non-empty list of distinct frames >= 0, at most
//    kMaxFrameSpecFrames, that reads back the same when written as "a,b,c" (lists up to
//    10,000 frames); every shard split of it is disjoint and covers it.
//  - expand_output_pattern / pattern_has_frame_field: both refuse the same patterns; a
//    pattern with a frame field names frames 7 and 8 differently, one without names them
//    the same; "{scene}" text appears only through the field.
inline void check_frame_spec(std::string_view input) {
    using namespace batch;
    std::vector<int> frames;
    bool refused = false;
    try {
        frames = parse_frame_spec(input);
    } catch (const SpecError&) {
        refused = true;
    }
    if (!refused) {
        if (frames.empty()) throw BatchInvariantBroken("a parsed spec has frames", input);
        if (frames.size() > static_cast<std::size_t>(kMaxFrameSpecFrames)) {
            throw BatchInvariantBroken("at most kMaxFrameSpecFrames frames", input);
        }
        std::unordered_set<int> seen;
        for (int f : frames) {
            if (f < 0) throw BatchInvariantBroken("frames are >= 0", input);
            if (!seen.insert(f).second)
                throw BatchInvariantBroken("frames are distinct", input);
        }
        if (frames.size() <= 10000) {
            std::string written;
            for (std::size_t i = 0; i < frames.size(); ++i) {
                if (i) written += ',';
                written += std::to_string(frames[i]);
            }
            if (parse_frame_spec(written) != frames) {
                throw BatchInvariantBroken("a written frame list reads back the same", input);
            }
            for (int count : {1, 2, 3, 7}) {
                std::multiset<int> all;
                for (int i = 0; i < count; ++i) {
                    const std::vector<int> part = select_shard(frames, {i, count});
                    all.insert(part.begin(), part.end());
                }
                if (all != std::multiset<int>(frames.begin(), frames.end())) {
                    throw BatchInvariantBroken("shards are disjoint and cover the list", input);
                }
            }
        }
    }

    bool has_frame = false;
    bool pattern_refused = false;
    try {
        has_frame = pattern_has_frame_field(input);
    } catch (const SpecError&) {
        pattern_refused = true;
    }
    std::string a, b;
    try {
        a = expand_output_pattern(input, 7, "S");
        b = expand_output_pattern(input, 8, "S");
    } catch (const SpecError&) {
        if (!pattern_refused) {
            throw BatchInvariantBroken("expand refuses what pattern_has_frame_field refuses",
                                       input);
        }
        return;
    }
    if (pattern_refused) {
        throw BatchInvariantBroken("pattern_has_frame_field refuses what expand refuses",
                                   input);
    }
    if (has_frame == (a == b)) {
        throw BatchInvariantBroken("a frame field makes frames 7 and 8 differ", input);
    }
    // Expansion only grows the text by the fields' values: a pattern of n bytes gives at
    // most n + (10 + 1) * n bytes (each field at least 1 byte, each value at most 10
    // digits or 1 byte of scene name; a '#' run pads to its own length).
    if (a.size() > input.size() * 12 + 16) {
        throw BatchInvariantBroken("expansion stays proportional to the pattern", input);
    }
}

// The input as a crop for three image sizes, and as a shard "i/n".
//  - parse_crop: SpecError, or 0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height.
//  - parse_shard: SpecError, or 0 <= index < count.
inline void check_crop_spec(std::string_view input) {
    using namespace batch;
    static constexpr int sizes[][2] = {{64, 48}, {1, 1}, {INT_MAX, INT_MAX}};
    for (const auto& size : sizes) {
        try {
            const PixelRect c = parse_crop(input, size[0], size[1]);
            if (!(0 <= c.x0 && c.x0 < c.x1 && c.x1 <= size[0] && 0 <= c.y0 && c.y0 < c.y1 &&
                  c.y1 <= size[1])) {
                throw BatchInvariantBroken("a parsed crop lies inside the image", input);
            }
        } catch (const SpecError&) {
        }
    }
    try {
        const Shard s = parse_shard(input);
        if (!(0 <= s.index && s.index < s.count)) {
            throw BatchInvariantBroken("a parsed shard has 0 <= index < count", input);
        }
    } catch (const SpecError&) {
    }
}

}  // namespace octray::fuzz
