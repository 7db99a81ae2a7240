// Numbers typed on the command line: comma-separated lists of finite numbers, as the editing commands
// take them (--plane, --at, --grab, --move, --pin).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace waxwork {

// Comma-separated finite numbers, exactly `count` of them, blanks allowed around each; `what` names
// the option in errors. A value beyond double's normal range (overflow, or underflow to a subnormal)
// is refused as not a finite number: it is a typing error, not a plane or a position.
std::vector<double> parse_numbers(const std::string& text, size_t count, const std::string& what);

}  // namespace waxwork
