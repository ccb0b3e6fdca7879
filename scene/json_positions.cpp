// A JSON path's place in the text (scene/json_positions.h): a scanner that walks the text
// down the path only, skipping every other value without building anything, so a scene of
// a million spheres is looked through in one pass.

#include "scene/json_positions.h"

#include <algorithm>
#include <cstdint>
#include <string>

#include "scene/json_messages.h"

namespace octray::scene_json {
namespace {

// The scene reader refuses deeper files (scene/json_dom.cpp); a text that gets here is at
// most that deep, and the bound keeps recursion safe on any other.
constexpr int kMaxDepth = 128;

class PathScanner {
  public:
    PathScanner(std::string_view text, std::string_view target)
        : text_(text), target_(target) {}

    std::optional<std::size_t> find() {
        skip_blanks();
        if (at_end()) return std::nullopt;
        best_offset_ = pos_;  // the root: the "" path
        best_length_ = 0;
        const std::string root;
        value(&root, 0);
        return best_offset_;
    }

  private:
    bool at_end() const { return pos_ >= text_.size(); }
    char peek() const { return at_end() ? '\0' : text_[pos_]; }

    void skip_blanks() {
        while (!at_end() &&
               (peek() == ' ' || peek() == '\t' || peek() == '\n' || peek() == '\r'))
            ++pos_;
    }

    // Whether `path` is the target or a parent of it.
    std::size_t match(const std::string& path) const {
        if (target_.size() < path.size() || target_.compare(0, path.size(), path) != 0)
            return 0;
        if (target_.size() == path.size()) return path.size();
        const char next = target_[path.size()];
        return next == '.' || next == '[' ? path.size() : 0;
    }

    // Records `offset` as where `path` is written, when `path` leads to the target at least
    // as far as the best so far (later duplicates win); returns whether to look inside.
    bool record(const std::string& path, std::size_t offset) {
        const std::size_t length = match(path);
        if (length == 0) return false;
        if (length >= best_length_) {
            best_length_ = length;
            best_offset_ = offset;
        }
        return length < target_.size();
    }

    static void append_utf8(std::string& out, std::uint32_t c) {
        if (c < 0x80) {
            out += static_cast<char>(c);
        } else if (c < 0x800) {
            out += static_cast<char>(0xC0 | (c >> 6));
            out += static_cast<char>(0x80 | (c & 0x3F));
        } else if (c < 0x10000) {
            out += static_cast<char>(0xE0 | (c >> 12));
            out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
            out += static_cast<char>(0x80 | (c & 0x3F));
        } else {
            out += static_cast<char>(0xF0 | (c >> 18));
            out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
            out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
            out += static_cast<char>(0x80 | (c & 0x3F));
        }
    }

    std::optional<std::uint32_t> hex4() {
        if (pos_ + 4 > text_.size()) return std::nullopt;
        std::uint32_t value = 0;
        for (int i = 0; i < 4; ++i) {
            const char c = text_[pos_++];
            value <<= 4;
            if (c >= '0' && c <= '9')
                value |= static_cast<std::uint32_t>(c - '0');
            else if (c >= 'a' && c <= 'f')
                value |= static_cast<std::uint32_t>(c - 'a' + 10);
            else if (c >= 'A' && c <= 'F')
                value |= static_cast<std::uint32_t>(c - 'A' + 10);
            else
                return std::nullopt;
        }
        return value;
    }

    // A string at pos_ (its opening quote), decoded into `out` when `out` is given.
    bool string(std::string* out) {
        ++pos_;
        while (!at_end()) {
            const char c = text_[pos_++];
            if (c == '"') return true;
            if (c != '\\') {
                if (out) *out += c;
                continue;
            }
            if (at_end()) return false;
            const char e = text_[pos_++];
            if (e == 'u') {
                std::optional<std::uint32_t> code = hex4();
                if (!code) return false;
                // A surrogate pair is one character.
                if (*code >= 0xD800 && *code < 0xDC00 && text_.substr(pos_, 2) == "\\u") {
                    pos_ += 2;
                    const std::optional<std::uint32_t> low = hex4();
                    if (!low) return false;
                    *code = 0x10000 + ((*code - 0xD800) << 10) + (*low - 0xDC00);
                }
                if (out) append_utf8(*out, *code);
                continue;
            }
            if (!out) continue;
            switch (e) {
                case 'b':
                    *out += '\b';
                    break;
                case 'f':
                    *out += '\f';
                    break;
                case 'n':
                    *out += '\n';
                    break;
                case 'r':
                    *out += '\r';
                    break;
                case 't':
                    *out += '\t';
                    break;
                default:
                    *out += e;  // " \ /
            }
        }
        return false;
    }

    // The value at pos_ whose path is `path`, looked into when it holds the target, or
    // skipped (`path` null); false where the text ends or stops being JSON.
    bool value(const std::string* path, int depth) {
        skip_blanks();
        if (at_end() || depth > kMaxDepth) return false;
        const char c = peek();
        if (c == '"') return string(nullptr);
        if (c == '{' || c == '[') return container(path, depth, c == '{');
        // A number or a literal: up to the next delimiter.
        while (!at_end() && peek() != ',' && peek() != '}' && peek() != ']' && peek() != ' ' &&
               peek() != '\t' && peek() != '\n' && peek() != '\r')
            ++pos_;
        return true;
    }

    bool container(const std::string* path, int depth, bool object) {
        const char close = object ? '}' : ']';
        ++pos_;
        skip_blanks();
        if (peek() == close) {
            ++pos_;
            return true;
        }
        for (std::size_t index = 0;; ++index) {
            skip_blanks();
            const std::size_t start = pos_;
            std::string child;
            if (object) {
                if (peek() != '"') return false;
                std::string key;
                if (!string(path ? &key : nullptr)) return false;
                skip_blanks();
                if (peek() != ':') return false;
                ++pos_;
                if (path) child = child_path(*path, key);
            } else if (path) {
                child = index_path(*path, index);
            }
            if (!value(path && record(child, start) ? &child : nullptr, depth + 1))
                return false;
            skip_blanks();
            if (peek() == ',') {
                ++pos_;
                continue;
            }
            if (peek() != close) return false;
            ++pos_;
            return true;
        }
    }

    std::string_view text_;
    std::string_view target_;
    std::size_t pos_ = 0;
    std::size_t best_offset_ = 0;
    std::size_t best_length_ = 0;
};

}  // namespace

SourcePosition text_position(std::string_view text, std::size_t offset) {
    SourcePosition at{1, 1};
    const std::size_t end = std::min(offset, text.size());
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < end; ++i) {
        if (text[i] == '\n') {
            ++at.line;
            line_start = i + 1;
        }
    }
    at.column = end - line_start + 1;
    return at;
}

std::optional<SourcePosition> json_path_position(std::string_view json_text,
                                                 std::string_view path) {
    // A byte order mark is no part of the JSON text.
    std::size_t skip = json_text.starts_with("\xEF\xBB\xBF") ? 3 : 0;
    PathScanner scanner(json_text.substr(skip), path);
    const std::optional<std::size_t> offset = scanner.find();
    if (!offset) return std::nullopt;
    return text_position(json_text, *offset + skip);
}

}  // namespace octray::scene_json
