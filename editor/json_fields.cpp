#include "editor/json_fields.h"

#include "tetops/error.h"

namespace waxwork {

std::string prefixed(const std::string& context, const std::string& message) {
    return context.empty() ? message : context + ": " + message;
}

void fail_json(const std::string& context, const std::string& message) {
    throw InvalidArgumentError(prefixed(context, message));
}

}  // namespace waxwork
