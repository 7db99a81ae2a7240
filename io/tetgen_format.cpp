#include "io/tetgen_format.h"

#include "base/error.h"
#include "io/ascii_numbers.h"
#include "io/atomic_file.h"
#include "io/file_contents.h"
#include "io/text_scanner.h"
#include "io/volume_checks.h"

namespace waxwork {
namespace {

struct TetGenNodes {
    std::vector<Eigen::Vector3d> positions;
    int64_t first_number = 0;
};

TetGenNodes parse_nodes(std::string_view contents, const std::string& file) {
    TextScanner scanner(contents, file, '#');
    const int64_t count = scanner.next_integer("number of points");
    const int64_t dimension = scanner.next_integer("dimension");
    const int64_t attributes = scanner.next_integer("number of attributes");
    const int64_t markers = scanner.next_integer("boundary marker flag");
    if (dimension != 3) scanner.fail("dimension " + std::to_string(dimension) + " is not supported (only 3)");
    if (markers != 0 && markers != 1) scanner.fail("boundary marker flag must be 0 or 1");
    scanner.check_count(attributes, 2, "attributes per point");
    scanner.check_count(count, 8, "points");
    TetGenNodes nodes;
    nodes.positions.resize(static_cast<size_t>(count));
    for (int64_t i = 0; i < count; ++i) {
        const int64_t number = scanner.next_integer("point number");
        if (i == 0) {
            if (number != 0 && number != 1) scanner.fail("the first point must be numbered 0 or 1");
            nodes.first_number = number;
        } else if (number != nodes.first_number + i) {
            scanner.fail("point numbers must be consecutive: expected " + std::to_string(nodes.first_number + i) +
                         ", found " + std::to_string(number));
        }
        Eigen::Vector3d& p = nodes.positions[static_cast<size_t>(i)];
        for (int k = 0; k < 3; ++k) p[k] = scanner.next_real("point coordinate");
        for (int64_t a = 0; a < attributes; ++a) scanner.next_real("point attribute");
        if (markers == 1) scanner.next_integer("boundary marker");
    }
    if (!scanner.at_end()) scanner.fail("unexpected content after the last of the " + std::to_string(count) + " points");
    return nodes;
}

std::vector<Tet> parse_elements(std::string_view contents, const std::string& file, const TetGenNodes& nodes) {
    TextScanner scanner(contents, file, '#');
    const int64_t count = scanner.next_integer("number of tetrahedra");
    const int64_t nodes_per_tet = scanner.next_integer("nodes per tetrahedron");
    const int64_t regions = scanner.next_integer("region attribute flag");
    if (nodes_per_tet != 4 && nodes_per_tet != 10) scanner.fail("nodes per tetrahedron must be 4 or 10");
    if (regions != 0 && regions != 1) scanner.fail("region attribute flag must be 0 or 1");
    scanner.check_count(count, 10, "tetrahedra");
    const auto point_count = static_cast<int64_t>(nodes.positions.size());
    std::vector<Tet> tets(static_cast<size_t>(count));
    for (int64_t t = 0; t < count; ++t) {
        const int64_t number = scanner.next_integer("tetrahedron number");
        for (int64_t k = 0; k < nodes_per_tet; ++k) {
            const int64_t point = scanner.next_integer("point number");
            const int64_t index = point - nodes.first_number;
            if (index < 0 || index >= point_count) {
                scanner.fail("tetrahedron " + std::to_string(number) + " references point " + std::to_string(point) +
                             " which does not exist (" + std::to_string(point_count) + " points numbered from " +
                             std::to_string(nodes.first_number) + ")");
            }
            if (k < 4) tets[static_cast<size_t>(t)][static_cast<size_t>(k)] = static_cast<int32_t>(index);
        }
        if (regions == 1) scanner.next_real("region attribute");
    }
    if (!scanner.at_end()) {
        scanner.fail("unexpected content after the last of the " + std::to_string(count) + " tetrahedra");
    }
    return tets;
}

std::filesystem::path with_extension(std::filesystem::path path, const char* extension) {
    return path.replace_extension(extension);
}

}  // namespace

TetMesh parse_tetgen(std::string_view node_contents, const std::string& node_file, std::string_view ele_contents,
                     const std::string& ele_file, VolumeMetadata* metadata) {
    TetGenNodes nodes = parse_nodes(node_contents, node_file);
    std::vector<Tet> tets = parse_elements(ele_contents, ele_file, nodes);
    if (tets.empty()) throw FileError(ele_file, "contains no tetrahedra");
    if (metadata) *metadata = find_metadata_comments(node_contents, "# ", node_file);
    return mesh_from_foreign_geometry(std::move(nodes.positions), std::move(tets), ele_file);
}

void format_tetgen_node(const TetMesh& mesh, std::ostream& out, const VolumeMetadata& metadata) {
    std::string text = metadata_comment_lines(metadata, "# ");
    text.reserve(mesh.vertex_count() * 72 + 64);
    append_number(text, static_cast<int64_t>(mesh.vertex_count()));
    // A boundary marker column (0: unmarked) ends every line with a one-character token, so a file
    // cut inside its last coordinate is detected as truncated instead of read as a shorter number.
    text += " 3 0 1\n";
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        append_number(text, static_cast<int64_t>(v));
        for (int k = 0; k < 3; ++k) {
            text += ' ';
            append_number(text, mesh.positions[v][k]);
        }
        text += " 0\n";
    }
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

void format_tetgen_ele(const TetMesh& mesh, std::ostream& out) {
    std::string text;
    text.reserve(mesh.tet_count() * 48 + 64);
    append_number(text, static_cast<int64_t>(mesh.tet_count()));
    text += " 4 1\n";
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        append_number(text, static_cast<int64_t>(t));
        for (const int32_t v : mesh.tets[t]) {
            text += ' ';
            append_number(text, int64_t{v});
        }
        text += ' ';
        append_number(text, t < mesh.piece_ids.size() ? int64_t{mesh.piece_ids[t]} : int64_t{0});
        text += '\n';
    }
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

void write_tetgen(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata) {
    write_files_atomically({
        FileWriter{with_extension(path, ".node"), [&](std::ostream& out) { format_tetgen_node(mesh, out, metadata); }},
        FileWriter{with_extension(path, ".ele"), [&](std::ostream& out) { format_tetgen_ele(mesh, out); }},
    });
}

TetMesh read_tetgen(const std::filesystem::path& path, VolumeMetadata* metadata) {
    const std::filesystem::path node_path = with_extension(path, ".node");
    const std::filesystem::path ele_path = with_extension(path, ".ele");
    const std::string node_contents = read_file_contents(node_path);
    const std::string ele_contents = read_file_contents(ele_path);
    return parse_tetgen(node_contents, node_path.string(), ele_contents, ele_path.string(), metadata);
}

}  // namespace waxwork
