// Lists of numbers written as text: "1,2,3" (light specs, session fields, command-line vectors).
#pragma once

#include <string_view>
#include <vector>

namespace waxwork {

// Parses comma-separated doubles into `values`, all of the text consumed. Returns false for an empty
// item, trailing text ("1,2,3x") or anything std::from_chars does not read as a number; a leading '+'
// is accepted. std::from_chars rather than stod: it is locale-independent and reports trailing garbage
// instead of ignoring it. Non-finite values ("inf", "nan") are returned as read: callers check ranges.
bool parse_number_list(std::string_view text, std::vector<double>& values);

}  // namespace waxwork
