#include "io/text_scanner.h"

#include "base/error.h"

#include <charconv>
#include <cmath>

namespace waxwork {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

std::string quoted(std::string_view token) {
    constexpr size_t kMaxShown = 32;
    std::string shown(token.substr(0, kMaxShown));
    for (char& c : shown)
        if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    return "'" + shown + (token.size() > kMaxShown ? "...'" : "'");
}

}  // namespace

TextScanner::TextScanner(std::string_view text, std::string file_name, char comment)
    : text_(text), file_name_(std::move(file_name)), comment_(comment) {}

void TextScanner::skip_space() {
    while (position_ < text_.size()) {
        const char c = text_[position_];
        if (c == '\n') {
            ++line_;
            ++position_;
        } else if (is_space(c)) {
            ++position_;
        } else if (comment_ != '\0' && c == comment_) {
            while (position_ < text_.size() && text_[position_] != '\n') ++position_;
        } else {
            return;
        }
    }
}

bool TextScanner::at_end() {
    skip_space();
    return position_ >= text_.size();
}

std::string_view TextScanner::peek_token() {
    skip_space();
    size_t end = position_;
    while (end < text_.size() && !is_space(text_[end]) && !(comment_ != '\0' && text_[end] == comment_)) ++end;
    return text_.substr(position_, end - position_);
}

std::string_view TextScanner::next_token(std::string_view what) {
    const std::string_view token = peek_token();
    if (token.empty()) fail("expected " + std::string(what) + ", found end of file");
    position_ += token.size();
    return token;
}

int64_t TextScanner::next_integer(std::string_view what) {
    const std::string_view token = next_token(what);
    int64_t value = 0;
    // from_chars rejects a leading '+'; accept it since C's scanf-based writers may emit it.
    const size_t skip = token.size() > 1 && token[0] == '+' ? 1 : 0;
    const auto [end, error] = std::from_chars(token.data() + skip, token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size()) {
        fail("expected " + std::string(what) + " (an integer), found " + quoted(token));
    }
    return value;
}

double TextScanner::next_real(std::string_view what) {
    const std::string_view token = next_token(what);
    double value = 0;
    const size_t skip = token.size() > 1 && token[0] == '+' ? 1 : 0;
    const auto [end, error] = std::from_chars(token.data() + skip, token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size()) {
        fail("expected " + std::string(what) + " (a number), found " + quoted(token));
    }
    if (!std::isfinite(value)) fail(std::string(what) + " is not finite: " + quoted(token));
    return value;
}

void TextScanner::skip_line() {
    while (position_ < text_.size() && text_[position_] != '\n') ++position_;
    if (position_ < text_.size()) {
        ++position_;
        ++line_;
    }
}

void TextScanner::skip_record() {
    skip_space();
    if (position_ >= text_.size()) fail("unexpected end of file");
    skip_line();
}

void TextScanner::check_count(int64_t count, size_t min_bytes_each, std::string_view what) {
    if (count < 0) fail("negative number of " + std::string(what) + " (" + std::to_string(count) + ")");
    const size_t remaining = text_.size() - position_;
    if (static_cast<uint64_t>(count) > remaining / min_bytes_each) {
        fail("claims " + std::to_string(count) + " " + std::string(what) +
             " but the rest of the file is too short to hold them (truncated?)");
    }
}

void TextScanner::fail(const std::string& problem) const {
    throw FileError(file_name_, "line " + std::to_string(line_) + ": " + problem);
}

}  // namespace waxwork
