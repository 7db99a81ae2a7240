// Reading JSON objects field by field for edit operations and session files, with one-line errors
// that name the object and the field ("s.json: step 3: paint: field 'sigma': expected a finite
// number") and reject unknown fields, so a typo in a hand-written session never falls back to a
// default silently.
#pragma once

#include "scene/edit_operation.h"

#include <nlohmann/json.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

namespace waxwork {

// "context: message", or just the message when the context is empty.
std::string prefixed(const std::string& context, const std::string& message);
// Throws InvalidArgumentError(prefixed(context, message)).
[[noreturn]] void fail_json(const std::string& context, const std::string& message);

// The JSON document in `path` (key order kept); FileError naming the file when it cannot be read or
// is not valid JSON.
nlohmann::ordered_json read_json_file(const std::filesystem::path& path);

// Reads the fields of one JSON object, naming the object and field in every error, and rejects
// fields nobody asked for (finish()).
class FieldReader {
public:
    using Json = nlohmann::ordered_json;

    FieldReader(const Json& json, std::string context) : json_(json), context_(std::move(context)) {
        if (!json_.is_object()) fail_json(context_, "expected a JSON object");
    }

    bool has(const std::string& key) const { return json_.contains(key); }
    std::string field(const std::string& key) const { return prefixed(context_, "field '" + key + "'"); }

    const Json& at(const std::string& key) {
        seen_.insert(key);
        if (!json_.contains(key)) fail_json(context_, "missing field '" + key + "'");
        return json_.at(key);
    }

    double number(const std::string& key) {
        const Json& v = at(key);
        if (!v.is_number() || !std::isfinite(v.get<double>())) fail_json(field(key), "expected a finite number");
        return v.get<double>();
    }
    double number(const std::string& key, double fallback) { return has(key) ? number(key) : fallback; }

    int64_t integer(const std::string& key) {
        const Json& v = at(key);
        if (!v.is_number_integer()) fail_json(field(key), "expected an integer");
        return v.get<int64_t>();
    }
    int64_t integer(const std::string& key, int64_t fallback) { return has(key) ? integer(key) : fallback; }

    bool boolean(const std::string& key, bool fallback) {
        if (!has(key)) return fallback;
        const Json& v = at(key);
        if (!v.is_boolean()) fail_json(field(key), "expected true or false");
        return v.get<bool>();
    }

    Eigen::Vector3d vector(const std::string& key) { return vector_from_json(at(key), field(key)); }

    std::vector<Eigen::Vector3d> points(const std::string& key) {
        const Json& v = at(key);
        if (!v.is_array()) fail_json(field(key), "expected an array of [x, y, z] points");
        std::vector<Eigen::Vector3d> result;
        for (size_t i = 0; i < v.size(); ++i)
            result.push_back(vector_from_json(v[i], field(key) + " point " + std::to_string(i)));
        return result;
    }

    TetMaterial material(const std::string& key) { return material_from_json(at(key), field(key)); }

    void ignore(const std::string& key) { seen_.insert(key); }

    void finish() const {
        for (auto it = json_.begin(); it != json_.end(); ++it)
            if (!seen_.count(it.key())) fail_json(context_, "unknown field '" + it.key() + "'");
    }

    const std::string& context() const { return context_; }

private:
    const Json& json_;
    std::string context_;
    std::set<std::string> seen_;
};

}  // namespace waxwork
