// Batch specifications: frame lists, output patterns, shards, crop rectangles
// (render/batch/spec.h; grammar and limits in tools/README.md).

#include "render/batch/spec.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <vector>

#include "core/decimal.h"
#include "scene/builtin.h"

namespace octray::batch {
namespace {

constexpr std::int64_t kMaxFrame = std::numeric_limits<int>::max();
// Long input is cut short in messages: a megabyte of spec must not make a megabyte message.
constexpr std::size_t kMaxQuoted = 64;

// The text in double quotes, control and non-ASCII bytes as \xNN, cut at kMaxQuoted.
std::string quote(std::string_view text) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out = "\"";
    const std::size_t n = std::min(text.size(), kMaxQuoted);
    for (std::size_t i = 0; i < n; ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c == '"' || c == '\\') {
            out += '\\';
            out += static_cast<char>(c);
        } else if (c < 0x20 || c >= 0x7f) {
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 15];
        } else {
            out += static_cast<char>(c);
        }
    }
    if (text.size() > n) out += "...";
    out += '"';
    return out;
}

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

// A decimal number of digits only (blanks around it trimmed), at most `max`. `what`
// names it in messages; `context` is the message's prefix (which spec, which item).
std::int64_t parse_number(std::string_view text, std::int64_t max, std::string_view what,
                          const std::string& context) {
    const std::string_view t = trim(text);
    if (t.empty()) {
        throw SpecError(context + "expected " + std::string(what) + ", found nothing");
    }
    if (t.front() == '-') {
        throw SpecError(context + "expected " + std::string(what) +
                        " (numbers start at 0), found " + quote(t));
    }
    if (!std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        throw SpecError(context + "expected " + std::string(what) +
                        " (decimal digits only), found " + quote(t));
    }
    const auto value = parse_decimal_digits(t);  // core/decimal.h, as the options read
    if (!value || *value > static_cast<std::uint64_t>(max)) {
        throw SpecError(context + "expected " + std::string(what) + " of at most " +
                        std::to_string(max) + ", found " + quote(t));
    }
    return static_cast<std::int64_t>(*value);
}

constexpr std::string_view kFrameSpecForms =
    "a frame \"5\", a range \"0-47\" or a range with a step \"1-100:2\", separated by commas";

}  // namespace

std::vector<int> parse_frame_spec(std::string_view spec) {
    const std::string head = "frame spec " + quote(spec) + ": ";
    if (trim(spec).empty()) {
        throw SpecError(head + "the frame list is empty; expected " +
                        std::string(kFrameSpecForms));
    }
    struct Item {
        std::int64_t first, last, step;
    };
    std::vector<Item> items;
    std::int64_t listed = 0;  // frames of all items, repeats included
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = spec.find(',', start);
        const std::string_view item =
            spec.substr(start, comma == spec.npos ? spec.npos : comma - start);
        const std::string context = head + "in item " + quote(trim(item)) + ": ";
        if (trim(item).empty()) {
            throw SpecError(head +
                            "empty item (two commas in a row, or a comma at an end); "
                            "expected " +
                            std::string(kFrameSpecForms));
        }
        // item := N | N-M | N-M:S. A leading '-' is a negative number, not a range.
        const std::string_view body = trim(item);
        const std::size_t dash = body.find('-', 1);
        const std::size_t colon = body.find(':');
        std::int64_t first = 0, last = 0, step = 1;
        if (dash == std::string_view::npos) {
            if (colon != std::string_view::npos) {
                throw SpecError(context +
                                "a step needs a range; expected N-M:S such as "
                                "\"1-100:2\"");
            }
            first = last = parse_number(body, kMaxFrame, "a frame number", context);
        } else {
            if (colon != std::string_view::npos && colon < dash) {
                throw SpecError(context +
                                "expected N-M:S (the step after the range), such as "
                                "\"1-100:2\"");
            }
            first = parse_number(body.substr(0, dash), kMaxFrame, "a first frame", context);
            const std::string_view rest = body.substr(dash + 1);
            const std::size_t c = rest.find(':');
            last =
                parse_number(rest.substr(0, c), kMaxFrame, "a last frame after '-'", context);
            if (c != std::string_view::npos) {
                step = parse_number(rest.substr(c + 1), kMaxFrame, "a step after ':'", context);
                if (step == 0) {
                    throw SpecError(context + "expected a step >= 1, found 0");
                }
            }
            if (last < first) {
                throw SpecError(context +
                                "the range runs backwards; expected the first frame <= "
                                "the last (write \"" +
                                std::to_string(last) + "-" + std::to_string(first) + "\")");
            }
        }
        const std::int64_t count = (last - first) / step + 1;
        listed += count;
        if (listed > kMaxFrameSpecFrames) {
            throw SpecError(head + "lists more than " + std::to_string(kMaxFrameSpecFrames) +
                            " frames; expected at most that many in one spec (split the job)");
        }
        items.push_back({first, last, step});
        if (comma == spec.npos) break;
        start = comma + 1;
    }
    // The frames of one item are distinct already; repeats need a set only across items.
    std::vector<int> frames;
    frames.reserve(static_cast<std::size_t>(listed));
    std::unordered_set<int> seen;
    if (items.size() > 1) seen.reserve(static_cast<std::size_t>(listed));
    for (const Item& item : items) {
        for (std::int64_t f = item.first; f <= item.last; f += item.step) {
            if (items.size() == 1 || seen.insert(static_cast<int>(f)).second) {
                frames.push_back(static_cast<int>(f));
            }
        }
    }
    return frames;
}

namespace {

// One piece of an output pattern: literal text, the frame (zero-padded to `width`
// digits, 0 for none), or the scene's name.
struct PatternPart {
    enum Kind { text, frame, scene } kind = text;
    std::string literal;
    std::size_t width = 0;
};

constexpr std::string_view kPatternFields =
    "expected {frame}, {frame:0Nd} with N from 1 to 9 (e.g. {frame:04d}), {scene}, a run of "
    "'#' for the zero-padded frame, or {{ and }} for literal braces";

std::vector<PatternPart> parse_pattern(std::string_view pattern) {
    const std::string head = "output pattern " + quote(pattern) + ": ";
    std::vector<PatternPart> parts;
    const auto add_text = [&parts](char c) {
        if (parts.empty() || parts.back().kind != PatternPart::text) parts.push_back({});
        parts.back().literal += c;
    };
    for (std::size_t i = 0; i < pattern.size();) {
        const char c = pattern[i];
        if (c == '#') {
            std::size_t j = i;
            while (j < pattern.size() && pattern[j] == '#') ++j;
            parts.push_back({PatternPart::frame, {}, j - i});
            i = j;
        } else if (c == '}') {
            if (i + 1 < pattern.size() && pattern[i + 1] == '}') {
                add_text('}');
                i += 2;
            } else {
                throw SpecError(head + "a lone '}' at position " + std::to_string(i) + "; " +
                                std::string(kPatternFields));
            }
        } else if (c == '{') {
            if (i + 1 < pattern.size() && pattern[i + 1] == '{') {
                add_text('{');
                i += 2;
                continue;
            }
            const std::size_t close = pattern.find('}', i);
            if (close == std::string_view::npos) {
                throw SpecError(head + "the '{' at position " + std::to_string(i) +
                                " is never closed; " + std::string(kPatternFields));
            }
            const std::string_view field = pattern.substr(i + 1, close - i - 1);
            if (field == "frame") {
                parts.push_back({PatternPart::frame, {}, 0});
            } else if (field == "scene") {
                parts.push_back({PatternPart::scene, {}, 0});
            } else if (field.size() == 9 && field.substr(0, 7) == "frame:0" &&
                       field[7] >= '1' && field[7] <= '9' && field[8] == 'd') {
                parts.push_back(
                    {PatternPart::frame, {}, static_cast<std::size_t>(field[7] - '0')});
            } else if (field.substr(0, 6) == "frame:") {
                throw SpecError(head + "unsupported frame format " +
                                quote("{" + std::string(field) + "}") + "; " +
                                std::string(kPatternFields));
            } else {
                throw SpecError(head + "unknown field " +
                                quote("{" + std::string(field) + "}") + "; " +
                                std::string(kPatternFields));
            }
            i = close + 1;
        } else {
            add_text(c);
            ++i;
        }
    }
    return parts;
}

}  // namespace

bool pattern_has_frame_field(std::string_view pattern) {
    const std::vector<PatternPart> parts = parse_pattern(pattern);
    return std::any_of(parts.begin(), parts.end(),
                       [](const PatternPart& p) { return p.kind == PatternPart::frame; });
}

std::string expand_output_pattern(std::string_view pattern, int frame,
                                  std::string_view scene_name) {
    if (frame < 0) {
        throw SpecError("output pattern " + quote(pattern) +
                        ": expected a frame number >= 0, found " + std::to_string(frame));
    }
    const std::string digits = std::to_string(frame);
    std::string out;
    for (const PatternPart& p : parse_pattern(pattern)) {
        switch (p.kind) {
            case PatternPart::text:
                out += p.literal;
                break;
            case PatternPart::frame:
                if (p.width > digits.size()) out.append(p.width - digits.size(), '0');
                out += digits;
                break;
            case PatternPart::scene:
                out += scene_name;
                break;
        }
    }
    return out;
}

Shard parse_shard(std::string_view text) {
    const std::string head = "shard " + quote(text) + ": ";
    const std::size_t slash = text.find('/');
    if (slash == std::string_view::npos) {
        throw SpecError(head + "expected i/n (shard i of n, 0 <= i < n), such as \"0/4\"");
    }
    const std::int64_t index =
        parse_number(text.substr(0, slash), kMaxFrame, "a shard index before '/'", head);
    const std::int64_t count =
        parse_number(text.substr(slash + 1), kMaxFrame, "a shard count after '/'", head);
    if (count < 1) throw SpecError(head + "expected a shard count >= 1, found 0");
    if (index >= count) {
        throw SpecError(head +
                        "expected a shard index below the count (shards are numbered 0 to " +
                        std::to_string(count - 1) + "), found " + std::to_string(index));
    }
    return {static_cast<int>(index), static_cast<int>(count)};
}

Shard shard_from_environment(const std::function<const char*(const char*)>& getenv_fn,
                             std::optional<int> shard_count) {
    const std::string head = "shard auto: ";
    if (shard_count && *shard_count < 1) {
        throw SpecError(head + "expected a shard count >= 1, found " +
                        std::to_string(*shard_count));
    }
    const auto get = [&getenv_fn](const char* name) -> std::optional<std::string> {
        const char* value = getenv_fn(name);
        if (value == nullptr || *value == '\0') return std::nullopt;
        return std::string(value);
    };
    const auto number = [&head](const char* name, const std::string& value) {
        return parse_number(value, kMaxFrame, "a non-negative integer",
                            head + name + "=" + quote(value) + ": ");
    };
    const auto checked = [&head](std::int64_t index, std::int64_t count,
                                 const std::string& how) -> Shard {
        if (index >= count) {
            throw SpecError(head + how + " gives shard " + std::to_string(index) + " of " +
                            std::to_string(count) +
                            "; expected an index below the count (an "
                            "array of consecutive task ids, or give the shard as i/n)");
        }
        return {static_cast<int>(index), static_cast<int>(count)};
    };

    if (const auto id_text = get("SLURM_ARRAY_TASK_ID")) {
        const std::int64_t id = number("SLURM_ARRAY_TASK_ID", *id_text);
        std::int64_t min = 0, step = 1;
        std::string how = "SLURM_ARRAY_TASK_ID=" + *id_text;
        if (const auto t = get("SLURM_ARRAY_TASK_MIN")) {
            min = number("SLURM_ARRAY_TASK_MIN", *t);
            how += ", SLURM_ARRAY_TASK_MIN=" + *t;
        }
        if (const auto t = get("SLURM_ARRAY_TASK_STEP")) {
            step = number("SLURM_ARRAY_TASK_STEP", *t);
            how += ", SLURM_ARRAY_TASK_STEP=" + *t;
            if (step < 1)
                throw SpecError(head + "SLURM_ARRAY_TASK_STEP=\"0\": expected a step >= 1");
        }
        if (id < min || (id - min) % step != 0) {
            throw SpecError(head + how + ": expected a task id of the form MIN + k * STEP");
        }
        std::optional<std::int64_t> count;
        if (const auto t = get("SLURM_ARRAY_TASK_COUNT")) {
            count = number("SLURM_ARRAY_TASK_COUNT", *t);
            how += ", SLURM_ARRAY_TASK_COUNT=" + *t;
            if (*count < 1)
                throw SpecError(head + "SLURM_ARRAY_TASK_COUNT=\"0\": expected a count >= 1");
            if (shard_count && *shard_count != *count) {
                throw SpecError(head + "the shard count " + std::to_string(*shard_count) +
                                " disagrees with SLURM_ARRAY_TASK_COUNT=" + *t +
                                "; expected the same count (or leave the shard count out)");
            }
        } else if (shard_count) {
            count = *shard_count;
        } else {
            throw SpecError(head +
                            "SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not; "
                            "expected both (Slurm sets them for job arrays), or a shard "
                            "count");
        }
        return checked((id - min) / step, *count, how);
    }
    if (const auto index_text = get("JOB_COMPLETION_INDEX")) {
        const std::int64_t index = number("JOB_COMPLETION_INDEX", *index_text);
        if (!shard_count) {
            throw SpecError(head + "JOB_COMPLETION_INDEX=" + *index_text +
                            " (a Kubernetes Indexed Job) gives the shard index but not the "
                            "count; expected a shard count too (the Job's completions)");
        }
        return checked(index, *shard_count, "JOB_COMPLETION_INDEX=" + *index_text);
    }
    throw SpecError(head +
                    "no array job found in the environment; expected SLURM_ARRAY_TASK_ID "
                    "(a Slurm job array) or JOB_COMPLETION_INDEX (a Kubernetes Indexed "
                    "Job), or give the shard as i/n");
}

void check_shard(Shard shard) {
    if (shard.count < 1 || shard.index < 0 || shard.index >= shard.count) {
        throw SpecError("shard " + std::to_string(shard.index) + "/" +
                        std::to_string(shard.count) + ": expected 0 <= index < count");
    }
}

PixelRect parse_crop(std::string_view text, int image_width, int image_height) {
    const std::string head = "crop " + quote(text) + ": ";
    std::vector<std::string_view> fields;
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = text.find(',', start);
        fields.push_back(text.substr(start, comma == text.npos ? text.npos : comma - start));
        if (comma == text.npos || fields.size() > 4) break;
        start = comma + 1;
    }
    if (fields.size() != 4) {
        throw SpecError(head +
                        "expected four pixel coordinates x0,y0,x1,y1 (columns x0 to x1 - 1, "
                        "rows y0 to y1 - 1), such as \"0,0,64,48\"");
    }
    static constexpr std::string_view names[4] = {"x0", "y0", "x1", "y1"};
    const std::int64_t limits[4] = {image_width, image_height, image_width, image_height};
    std::int64_t v[4];
    for (int i = 0; i < 4; ++i) {
        v[i] = parse_number(
            fields[static_cast<std::size_t>(i)], std::max<std::int64_t>(limits[i], 0),
            std::string(names[i]) + " (a pixel coordinate within the " +
                std::to_string(image_width) + " x " + std::to_string(image_height) + " image)",
            head);
    }
    if (v[0] >= v[2]) {
        throw SpecError(head +
                        "expected x0 < x1 (a crop at least one pixel wide), found x0 = " +
                        std::to_string(v[0]) + ", x1 = " + std::to_string(v[2]));
    }
    if (v[1] >= v[3]) {
        throw SpecError(head +
                        "expected y0 < y1 (a crop at least one pixel high), found y0 = " +
                        std::to_string(v[1]) + ", y1 = " + std::to_string(v[3]));
    }
    return {static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<int>(v[2]),
            static_cast<int>(v[3])};
}

std::string scene_display_name(std::string_view scene_spec) {
    const std::string spec(scene_spec);
    std::string stem;
    if (is_builtin_scene(spec)) {
        stem = spec.substr(0, spec.find(','));
        const std::size_t colon = stem.find(':');
        if (colon != std::string::npos) stem[colon] = '-';
    } else {
        stem = std::filesystem::path(spec).stem().string();
    }
    for (char& c : stem) {
        const auto u = static_cast<unsigned char>(c);
        if (!std::isalnum(u) && c != '-' && c != '_' && c != '.') c = '_';
    }
    if (stem.empty() || stem == "." || stem == "..") stem = "render";
    return stem;
}

}  // namespace octray::batch
