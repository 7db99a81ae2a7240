#include "io/medit_format.h"

#include "base/error.h"
#include "io/ascii_numbers.h"
#include "io/atomic_file.h"
#include "io/file_contents.h"
#include "io/text_scanner.h"
#include "io/volume_checks.h"

#include <cctype>

namespace waxwork {
namespace {

bool same_keyword(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
    return true;
}

bool is_keyword(std::string_view token) {
    return !token.empty() && std::isalpha(static_cast<unsigned char>(token[0]));
}

}  // namespace

TetMesh parse_medit(std::string_view contents, const std::string& file, VolumeMetadata* metadata) {
    TextScanner scanner(contents, file, '#');
    if (!same_keyword(scanner.peek_token(), "MeshVersionFormatted")) {
        scanner.fail("not a MEDIT file (it does not start with MeshVersionFormatted)");
    }
    scanner.next_token("MeshVersionFormatted");
    const int64_t version = scanner.next_integer("mesh version");
    if (version < 1 || version > 4) scanner.fail("unsupported MeshVersionFormatted " + std::to_string(version));

    bool have_dimension = false;
    bool have_vertices = false;
    bool have_end = false;
    std::vector<Eigen::Vector3d> positions;
    std::vector<Tet> tets;
    while (!scanner.at_end()) {
        const std::string_view keyword = scanner.next_token("keyword");
        if (!is_keyword(keyword)) {
            scanner.fail("expected a keyword, found '" + std::string(keyword.substr(0, 32)) + "'");
        }
        if (same_keyword(keyword, "End")) {
            have_end = true;
            break;
        }
        if (same_keyword(keyword, "Dimension")) {
            const int64_t dimension = scanner.next_integer("dimension");
            if (dimension != 3) scanner.fail("Dimension " + std::to_string(dimension) + " is not supported (only 3)");
            have_dimension = true;
        } else if (same_keyword(keyword, "Vertices")) {
            if (!have_dimension) scanner.fail("Vertices before Dimension");
            if (have_vertices) scanner.fail("more than one Vertices section");
            const int64_t count = scanner.next_integer("number of vertices");
            scanner.check_count(count, 8, "vertices");
            positions.resize(static_cast<size_t>(count));
            for (Eigen::Vector3d& p : positions) {
                for (int k = 0; k < 3; ++k) p[k] = scanner.next_real("vertex coordinate");
                scanner.next_integer("vertex ref");
            }
            have_vertices = true;
        } else if (same_keyword(keyword, "Tetrahedra")) {
            if (!have_vertices) scanner.fail("Tetrahedra before Vertices");
            const int64_t count = scanner.next_integer("number of tetrahedra");
            scanner.check_count(count, 10, "tetrahedra");
            tets.reserve(tets.size() + static_cast<size_t>(count));
            const auto vertex_count = static_cast<int64_t>(positions.size());
            for (int64_t t = 0; t < count; ++t) {
                Tet tet;
                for (int k = 0; k < 4; ++k) {
                    const int64_t vertex = scanner.next_integer("vertex number");
                    if (vertex < 1 || vertex > vertex_count) {
                        scanner.fail("tetrahedron " + std::to_string(tets.size() + 1) + " references vertex " +
                                     std::to_string(vertex) + " which does not exist (" +
                                     std::to_string(vertex_count) + " vertices)");
                    }
                    tet[k] = static_cast<int32_t>(vertex - 1);
                }
                scanner.next_integer("tetrahedron ref");
                tets.push_back(tet);
            }
        } else if (same_keyword(keyword, "Hexahedra") || same_keyword(keyword, "Prisms") ||
                   same_keyword(keyword, "Pyramids")) {
            // Other volume elements: skipping them would drop part of the volume silently.
            const int64_t count = scanner.next_integer("number of elements");
            if (count != 0)
                scanner.fail("contains " + std::to_string(count) + " " + std::string(keyword) +
                             "; Waxwork reads volumes of tetrahedra only (split them into tetrahedra first)");
        } else {
            // Surface and other sections (Triangles, Edges, Corners, ...): their entries are numbers,
            // so skip up to the next keyword.
            while (!scanner.at_end() && !is_keyword(scanner.peek_token())) scanner.next_token("number");
        }
    }
    if (!have_end) scanner.fail("missing End keyword (truncated file?)");
    if (tets.empty()) throw FileError(file, "contains no tetrahedra");
    if (metadata) *metadata = find_metadata_comments(contents, "# ", file);
    return mesh_from_foreign_geometry(std::move(positions), std::move(tets), file);
}

void format_medit(const TetMesh& mesh, std::ostream& out, const VolumeMetadata& metadata) {
    std::string text;
    text.reserve(mesh.vertex_count() * 72 + mesh.tet_count() * 40 + 256);
    text += "MeshVersionFormatted 2\n";
    text += metadata_comment_lines(metadata, "# ");
    text += "\nDimension 3\n\nVertices\n";
    append_number(text, static_cast<int64_t>(mesh.vertex_count()));
    text += '\n';
    for (const Eigen::Vector3d& p : mesh.positions) {
        for (int k = 0; k < 3; ++k) {
            append_number(text, p[k]);
            text += ' ';
        }
        text += "0\n";
    }
    text += "\nTetrahedra\n";
    append_number(text, static_cast<int64_t>(mesh.tet_count()));
    text += '\n';
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        for (const int32_t v : mesh.tets[t]) {
            append_number(text, int64_t{v} + 1);
            text += ' ';
        }
        append_number(text, t < mesh.piece_ids.size() ? int64_t{mesh.piece_ids[t]} : int64_t{0});
        text += '\n';
    }
    text += "\nEnd\n";
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

void write_medit(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata) {
    write_file_atomically(path, [&](std::ostream& out) { format_medit(mesh, out, metadata); });
}

TetMesh read_medit(const std::filesystem::path& path, VolumeMetadata* metadata) {
    return parse_medit(read_file_contents(path), path.string(), metadata);
}

}  // namespace waxwork
