// Lists of numbers written as text: "1,2,3" (light specs, session fields, command-line vectors).
#pragma once

#include <string_view>
#include <vector>

namespace waxwork {

// Whether blanks (std::isspace) may stand around each number: Tight for "1,2,3" (light specs, session
// fields, --slice-normal), Blanks for the edit commands' --plane, --at and fractions, which users type
// quoted as "1, 0, 0, 0".
enum class NumberSpacing { Tight, Blanks };

// Parses comma-separated doubles into `values`, all of the text consumed. Returns false for an empty
// item, trailing text ("1,2,3x") or anything std::from_chars does not read as a number; one leading
// sign, '+' or '-', is accepted. With NumberSpacing::Blanks, blanks before and after each number are
// skipped (an item of blanks alone is still empty). std::from_chars rather than stod: it is
// locale-independent and reports trailing garbage instead of ignoring it. Non-finite values ("inf",
// "nan") are returned as read: callers check ranges.
bool parse_number_list(std::string_view text, std::vector<double>& values,
                       NumberSpacing spacing = NumberSpacing::Tight);

}  // namespace waxwork
