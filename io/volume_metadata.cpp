#include "io/volume_metadata.h"

#include "base/error.h"
#include "io/ascii_numbers.h"
#include "tetops/model_scale.h"

#include <charconv>

namespace waxwork {
namespace {

constexpr std::string_view kScaleKey = "waxwork mm_per_unit ";
// The writers put the line at the top; looking no further keeps reading a large mesh one pass.
constexpr size_t kHeaderBytes = 4096;

}  // namespace

void check_metadata(const VolumeMetadata& metadata, const std::string& file) {
    if (!metadata.mm_per_unit) return;
    const std::string problem = mm_per_unit_problem(*metadata.mm_per_unit);
    if (!problem.empty()) throw FileError(file, "stored mm_per_unit " + problem);
}

std::string metadata_comment_lines(const VolumeMetadata& metadata, std::string_view comment_prefix) {
    std::string text;
    if (!metadata.mm_per_unit) return text;
    text.append(comment_prefix).append(kScaleKey);
    append_number(text, *metadata.mm_per_unit);
    text += '\n';
    return text;
}

VolumeMetadata find_metadata_comments(std::string_view contents, std::string_view comment_prefix,
                                      const std::string& file) {
    VolumeMetadata metadata;
    contents = contents.substr(0, kHeaderBytes);
    size_t begin = 0;
    while (begin < contents.size()) {
        size_t end = contents.find('\n', begin);
        if (end == std::string_view::npos) end = contents.size();
        std::string_view line = contents.substr(begin, end - begin);
        begin = end + 1;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (!line.starts_with(comment_prefix) || !line.substr(comment_prefix.size()).starts_with(kScaleKey)) continue;
        const std::string_view value = line.substr(comment_prefix.size() + kScaleKey.size());
        double scale = 0;
        const auto [rest, error] = std::from_chars(value.data(), value.data() + value.size(), scale);
        if (error != std::errc() || rest != value.data() + value.size())
            throw FileError(file, "stored mm_per_unit '" + std::string(value.substr(0, 32)) + "' is not a number");
        if (metadata.mm_per_unit) throw FileError(file, "stores mm_per_unit more than once");
        metadata.mm_per_unit = scale;
    }
    check_metadata(metadata, file);
    return metadata;
}

}  // namespace waxwork
