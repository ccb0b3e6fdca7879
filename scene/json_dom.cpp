// The diagnosing reader's DOM (scene/json_dom.h): nlohmann's SAX parser driving a builder
// of our own.

#include "scene/json_dom.h"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "scene/json_positions.h"
#include "scene/scene_error.h"

namespace octray::scene_json {
namespace {

// Recursion is bounded by the scene schema anyway; this only stops absurd files early.
constexpr std::size_t kMaxNesting = 64;

// JSON text to a DOM, with positions for syntax errors and paths for duplicate keys.
// nlohmann's own DOM parser silently keeps the last of two equal keys and reports number
// overflow without a position, so we build the DOM through our own SAX handler.

struct ParseFailure {
    std::string path;
    std::string message;
    SourcePosition at = {};  // line 0: where `path` is written (json_path_position)
};

class DomBuilder final : public nlohmann::json_sax<Json> {
  public:
    explicit DomBuilder(std::string_view text) : text_(text) {}

    bool null() override { return add(Json(nullptr)); }
    bool boolean(bool value) override { return add(Json(value)); }
    bool number_integer(number_integer_t value) override { return add(Json(value)); }
    bool number_unsigned(number_unsigned_t value) override { return add(Json(value)); }
    bool number_float(number_float_t value, const string_t& /*text*/) override {
        return add(Json(value));
    }
    bool string(string_t& value) override { return add(Json(std::move(value))); }
    bool binary(binary_t& /*value*/) override {
        failure_ = ParseFailure{current_path(), "binary values are not JSON", {}};
        return false;
    }
    bool start_object(std::size_t /*elements*/) override {
        return add(Json::object()) && open(false);
    }
    bool key(string_t& name) override {
        Frame& frame = frames_.back();
        frame.key = name;
        if (!frame.keys.insert(name).second) {
            failure_ = ParseFailure{
                current_path(),
                "duplicate key " + quote_text(name) + " (each key may appear once per object)",
                {}};
            return false;
        }
        return true;
    }
    bool end_object() override {
        frames_.pop_back();
        return true;
    }
    bool start_array(std::size_t /*elements*/) override {
        return add(Json::array()) && open(true);
    }
    bool end_array() override {
        frames_.pop_back();
        return true;
    }
    bool parse_error(std::size_t position, const std::string& last_token,
                     const Json::exception& ex) override {
        // nlohmann reports the number of bytes read, the offending one included.
        const SourcePosition at =
            text_position(text_, position == 0 ? 0 : std::min(position - 1, text_.size()));
        if (ex.id == 406) {
            // nlohmann's "number overflow": a literal such as 1e999 that is no finite double.
            failure_ = ParseFailure{current_path(true),
                                    "expected a finite number, found " + last_token +
                                        ", which overflows to infinity",
                                    at};
            return false;
        }
        // Drop nlohmann's "[json.exception...] parse error at line L, column C: " prefix;
        // we give the position ourselves.
        std::string what = ex.what();
        const std::size_t col = what.find("column ");
        const std::size_t colon = col == std::string::npos ? col : what.find(": ", col);
        if (colon != std::string::npos) what = what.substr(colon + 2);
        failure_ = ParseFailure{"", "invalid JSON: " + what, at};
        return false;
    }

    Json& root() { return root_; }
    const std::optional<ParseFailure>& failure() const { return failure_; }

  private:
    struct Frame {
        Json* container;
        bool is_array;
        std::size_t count = 0;  // elements so far (arrays)
        std::string key;        // member being read (objects)
        std::unordered_set<std::string> keys;
    };

    bool add(Json value) {
        if (frames_.empty()) {
            root_ = std::move(value);
            current_ = &root_;
            return true;
        }
        Frame& frame = frames_.back();
        if (frame.is_array) {
            frame.container->push_back(std::move(value));
            ++frame.count;
            current_ = &frame.container->back();
        } else {
            Json& slot = (*frame.container)[frame.key];
            slot = std::move(value);
            current_ = &slot;
        }
        return true;
    }

    bool open(bool is_array) {
        if (frames_.size() >= kMaxNesting) {
            failure_ = ParseFailure{current_path(),
                                    "nesting deeper than " + std::to_string(kMaxNesting) +
                                        " levels; no scene needs that",
                                    {}};
            return false;
        }
        // The container just added stays put: its parent gains no element until it closes.
        frames_.push_back(Frame{current_, is_array, 0, {}, {}});
        return true;
    }

    // The path of the value read last, or with `pending` of the value being read (in an
    // array that is the element after the last one added).
    std::string current_path(bool pending = false) const {
        std::string path;
        for (std::size_t i = 0; i < frames_.size(); ++i) {
            const Frame& f = frames_[i];
            const bool next = pending && i + 1 == frames_.size();
            path = f.is_array
                       ? index_path(path, next ? f.count : (f.count == 0 ? 0 : f.count - 1))
                       : child_path(path, f.key);
        }
        return path;
    }

    std::string_view text_;
    Json root_;
    Json* current_ = nullptr;
    std::vector<Frame> frames_;
    std::optional<ParseFailure> failure_;
};

}  // namespace

Json parse_json_dom(std::string_view json_text, const std::string& source) {
    // The JSON library ends its input at a NUL byte, which would let anything after one
    // pass unread; strict JSON means the whole file, and JSON text never holds a NUL.
    if (const std::size_t nul = json_text.find('\0'); nul != std::string_view::npos)
        throw SceneError(source, text_position(json_text, nul), "", nul_byte_message());
    DomBuilder builder(json_text);
    const bool ok = Json::sax_parse(json_text, &builder, Json::input_format_t::json,
                                    /*strict=*/true, /*ignore_comments=*/false);
    if (!ok || builder.failure()) {
        const ParseFailure failure =
            builder.failure() ? *builder.failure() : ParseFailure{"", "invalid JSON", {}};
        // A duplicate key or a too deep nesting: where its path is written.
        SourcePosition at = failure.at;
        if (at.line == 0)
            at = json_path_position(json_text, failure.path).value_or(SourcePosition{});
        throw SceneError(source, at, failure.path, failure.message);
    }
    return std::move(builder.root());
}

}  // namespace octray::scene_json
