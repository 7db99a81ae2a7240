#include "base/number_list.h"

#include <charconv>
#include <system_error>

namespace waxwork {

bool parse_number_list(std::string_view text, std::vector<double>& values) {
    values.clear();
    while (true) {
        const size_t comma = text.find(',');
        const std::string_view item = text.substr(0, comma);
        double value = 0;
        const char* begin = item.data();
        const char* end = item.data() + item.size();
        if (!item.empty() && *begin == '+') ++begin;  // from_chars refuses a leading '+'
        const auto [ptr, ec] = std::from_chars(begin, end, value);
        if (ec != std::errc() || ptr != end || begin == end) return false;
        values.push_back(value);
        if (comma == std::string_view::npos) return true;
        text.remove_prefix(comma + 1);
    }
}

}  // namespace waxwork
