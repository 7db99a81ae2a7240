#include "scene/json_fields.h"

#include "base/error.h"
#include "io/file_contents.h"

namespace waxwork {

std::string prefixed(const std::string& context, const std::string& message) {
    return context.empty() ? message : context + ": " + message;
}

void fail_json(const std::string& context, const std::string& message) {
    throw InvalidArgumentError(prefixed(context, message));
}

nlohmann::ordered_json read_json_file(const std::filesystem::path& path) {
    const std::string text = read_file_contents(path);
    try {
        return nlohmann::ordered_json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        // parse_error, and out_of_range for a number no double holds (1e400).
        throw FileError(path.string(), std::string("not valid JSON: ") + e.what());
    }
}

}  // namespace waxwork
