#include "base/number_list.h"

#include <cctype>
#include <charconv>
#include <system_error>

namespace waxwork {

namespace {

bool is_blank(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

}  // namespace

bool parse_number_list(std::string_view text, std::vector<double>& values, NumberSpacing spacing) {
    values.clear();
    while (true) {
        const size_t comma = text.find(',');
        std::string_view item = text.substr(0, comma);
        if (spacing == NumberSpacing::Blanks) {
            while (!item.empty() && is_blank(item.front())) item.remove_prefix(1);
            while (!item.empty() && is_blank(item.back())) item.remove_suffix(1);
        }
        double value = 0;
        const char* begin = item.data();
        const char* end = item.data() + item.size();
        if (!item.empty() && *begin == '+') {
            ++begin;  // from_chars refuses a leading '+'
            if (begin != end && *begin == '-') return false;  // "+-1" is no number
        }
        const auto [ptr, ec] = std::from_chars(begin, end, value);
        if (ec != std::errc() || ptr != end || begin == end) return false;
        values.push_back(value);
        if (comma == std::string_view::npos) return true;
        text.remove_prefix(comma + 1);
    }
}

}  // namespace waxwork
