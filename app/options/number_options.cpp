#include "app/options/number_options.h"

#include "base/error.h"
#include "base/number_list.h"

#include <algorithm>
#include <cmath>

namespace waxwork {

std::vector<double> parse_numbers(const std::string& text, size_t count, const std::string& what) {
    std::vector<double> values;
    const bool numbers = parse_number_list(text, values, NumberSpacing::Blanks) &&
                         std::all_of(values.begin(), values.end(), [](double v) {
                             return v == 0 || std::isnormal(v);
                         });
    if (!numbers)
        throw InvalidArgumentError(what + ": \"" + text + "\" is not " +
                                   (count == 1 ? std::string("a finite number")
                                               : std::to_string(count) + " comma-separated finite numbers"));
    if (values.size() != count)
        throw InvalidArgumentError(what + ": expected " + std::to_string(count) + " comma-separated numbers, got " +
                                   std::to_string(values.size()) + " in \"" + text + "\"");
    return values;
}

}  // namespace waxwork
