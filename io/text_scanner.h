// A whitespace-separated token reader for the ASCII mesh formats (Gmsh, MEDIT, TetGen).
//
// Those formats are streams of numbers and keywords with line-oriented records; iostream extraction
// is slow (locale, per-character virtual calls) and reports no position, so this scanner walks an
// in-memory buffer with std::from_chars (exact for doubles) and puts "line N" in every error.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace waxwork {

class TextScanner {
public:
    // `comment` starts a comment running to the end of the line ('\0' for none).
    TextScanner(std::string_view text, std::string file_name, char comment = '\0');

    // True when only whitespace and comments remain.
    bool at_end();

    // The next token; throws FileError ("line N: expected WHAT, found end of file") at the end.
    std::string_view next_token(std::string_view what);
    // The next token without consuming it; empty at the end.
    std::string_view peek_token();

    // Integers and reals; `what` names the value in error messages. Reals must be finite.
    int64_t next_integer(std::string_view what);
    double next_real(std::string_view what);

    // Consumes the rest of the current line.
    void skip_line();
    // Skips blank lines, then consumes the next non-blank line.
    void skip_record();

    // Throws FileError if `count` records of at least `min_bytes_each` cannot fit in the unread
    // text: catches truncated files early and keeps absurd counts from allocating gigabytes.
    void check_count(int64_t count, size_t min_bytes_each, std::string_view what);

    size_t line() const { return line_; }
    const std::string& file_name() const { return file_name_; }

    // Throws FileError("FILE", "line N: PROBLEM").
    [[noreturn]] void fail(const std::string& problem) const;

private:
    void skip_space();

    std::string_view text_;
    size_t position_ = 0;
    size_t line_ = 1;
    std::string file_name_;
    char comment_;
};

}  // namespace waxwork
