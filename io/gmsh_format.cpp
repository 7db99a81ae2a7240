#include "io/gmsh_format.h"

#include "base/error.h"
#include "io/ascii_numbers.h"
#include "io/atomic_file.h"
#include "io/file_contents.h"
#include "io/text_scanner.h"
#include "io/volume_checks.h"

#include <unordered_map>

namespace waxwork {
namespace {

constexpr int64_t kGmshTetrahedron = 4;

void expect_token(TextScanner& scanner, std::string_view expected) {
    const std::string_view token = scanner.next_token(expected);
    if (token != expected) {
        scanner.fail("expected " + std::string(expected) + ", found '" + std::string(token.substr(0, 32)) + "'");
    }
}

struct GmshNodes {
    std::vector<Eigen::Vector3d> positions;
    std::unordered_map<int64_t, int32_t> index_of_tag;
};

// The first line of a $Nodes or $Elements section: the counts of blocks and of `item`s (then the
// smallest and largest tag, unused), each checked against what the rest of the file can hold (a block
// header takes at least 8 bytes, an item `item_bytes`).
struct SectionCounts {
    int64_t blocks = 0, items = 0;
};
SectionCounts read_section_counts(TextScanner& scanner, const std::string& item, size_t item_bytes) {
    SectionCounts counts;
    counts.blocks = scanner.next_integer("number of " + item + " blocks");
    counts.items = scanner.next_integer("number of " + item + "s");
    scanner.next_integer("minimum " + item + " tag");
    scanner.next_integer("maximum " + item + " tag");
    scanner.check_count(counts.blocks, 8, item + " blocks");
    scanner.check_count(counts.items, item_bytes, item + "s");
    return counts;
}

GmshNodes read_nodes(TextScanner& scanner) {
    const auto [block_count, node_count] = read_section_counts(scanner, "node", 8);
    GmshNodes nodes;
    nodes.positions.reserve(static_cast<size_t>(node_count));
    nodes.index_of_tag.reserve(static_cast<size_t>(node_count));
    std::vector<int64_t> tags;
    for (int64_t block = 0; block < block_count; ++block) {
        const int64_t entity_dimension = scanner.next_integer("entity dimension");
        scanner.next_integer("entity tag");
        const int64_t parametric = scanner.next_integer("parametric flag");
        const int64_t count = scanner.next_integer("number of nodes in block");
        if (entity_dimension < 0 || entity_dimension > 3) {
            scanner.fail("entity dimension " + std::to_string(entity_dimension) + " is not 0..3");
        }
        if (parametric != 0 && parametric != 1) scanner.fail("parametric flag must be 0 or 1");
        scanner.check_count(count, 8, "nodes in block");
        if (static_cast<int64_t>(nodes.positions.size()) + count > node_count) {
            scanner.fail("node blocks hold more nodes than the " + std::to_string(node_count) + " announced");
        }
        tags.resize(static_cast<size_t>(count));
        for (int64_t& tag : tags) tag = scanner.next_integer("node tag");
        for (const int64_t tag : tags) {
            Eigen::Vector3d p;
            for (int k = 0; k < 3; ++k) p[k] = scanner.next_real("node coordinate");
            // Parametric nodes carry entity_dimension extra coordinates (u, v, w) that we do not use.
            if (parametric == 1)
                for (int64_t k = 0; k < entity_dimension; ++k) scanner.next_real("parametric coordinate");
            if (tag <= 0) scanner.fail("node tag " + std::to_string(tag) + " is not positive");
            const auto [where, inserted] =
                nodes.index_of_tag.emplace(tag, static_cast<int32_t>(nodes.positions.size()));
            if (!inserted) scanner.fail("node tag " + std::to_string(tag) + " appears twice");
            nodes.positions.push_back(p);
        }
    }
    if (static_cast<int64_t>(nodes.positions.size()) != node_count) {
        scanner.fail("node blocks hold " + std::to_string(nodes.positions.size()) + " nodes, but " +
                     std::to_string(node_count) + " were announced");
    }
    expect_token(scanner, "$EndNodes");
    return nodes;
}

std::vector<Tet> read_tets(TextScanner& scanner, const GmshNodes& nodes) {
    const auto [block_count, element_count] = read_section_counts(scanner, "element", 2);
    std::vector<Tet> tets;
    int64_t seen = 0;
    for (int64_t block = 0; block < block_count; ++block) {
        scanner.next_integer("entity dimension");
        scanner.next_integer("entity tag");
        const int64_t type = scanner.next_integer("element type");
        const int64_t count = scanner.next_integer("number of elements in block");
        scanner.check_count(count, 2, "elements in block");
        seen += count;
        if (seen > element_count) {
            scanner.fail("element blocks hold more elements than the " + std::to_string(element_count) + " announced");
        }
        if (type != kGmshTetrahedron) {
            // One element per line; the node count of other types need not be known to skip them.
            scanner.skip_line();
            for (int64_t e = 0; e < count; ++e) scanner.skip_record();
            continue;
        }
        scanner.check_count(count, 10, "tetrahedra");
        tets.reserve(tets.size() + static_cast<size_t>(count));
        for (int64_t e = 0; e < count; ++e) {
            const int64_t element_tag = scanner.next_integer("element tag");
            Tet tet;
            for (int k = 0; k < 4; ++k) {
                const int64_t node_tag = scanner.next_integer("node tag");
                const auto found = nodes.index_of_tag.find(node_tag);
                if (found == nodes.index_of_tag.end()) {
                    scanner.fail("tet " + std::to_string(element_tag) + " references node " + std::to_string(node_tag) +
                                 " which does not exist");
                }
                tet[k] = found->second;
            }
            tets.push_back(tet);
        }
    }
    if (seen != element_count) {
        scanner.fail("element blocks hold " + std::to_string(seen) + " elements, but " +
                     std::to_string(element_count) + " were announced");
    }
    expect_token(scanner, "$EndElements");
    return tets;
}

}  // namespace

TetMesh parse_gmsh(std::string_view contents, const std::string& file, VolumeMetadata* metadata) {
    TextScanner scanner(contents, file);
    if (scanner.peek_token() != "$MeshFormat") scanner.fail("not a Gmsh file (it does not start with $MeshFormat)");
    GmshNodes nodes;
    std::vector<Tet> tets;
    bool have_nodes = false;
    bool have_elements = false;
    while (!scanner.at_end()) {
        const std::string section(scanner.next_token("section"));
        if (section == "$MeshFormat") {
            const std::string_view version = scanner.next_token("format version");
            if (version != "4.1") {
                scanner.fail("unsupported Gmsh format version " + std::string(version.substr(0, 16)) +
                             " (only 4.1 is supported)");
            }
            if (scanner.next_integer("file type") != 0) {
                scanner.fail("binary Gmsh files are not supported (save as ASCII)");
            }
            const int64_t data_size = scanner.next_integer("data size");
            if (data_size != 8) scanner.fail("data size must be 8");
            expect_token(scanner, "$EndMeshFormat");
        } else if (section == "$Nodes") {
            if (have_nodes) scanner.fail("more than one $Nodes section");
            nodes = read_nodes(scanner);
            have_nodes = true;
        } else if (section == "$Elements") {
            if (have_elements) scanner.fail("more than one $Elements section");
            if (!have_nodes) scanner.fail("$Elements before $Nodes");
            tets = read_tets(scanner, nodes);
            have_elements = true;
        } else if (section.size() > 1 && section[0] == '$' && section.rfind("$End", 0) != 0) {
            // $Entities, $PhysicalNames, $Periodic, $NodeData, ...: skip to the matching end marker.
            const std::string end = "$End" + section.substr(1);
            while (scanner.next_token(end) != end) {
            }
        } else {
            scanner.fail("unexpected '" + section.substr(0, 32) + "' outside a section");
        }
    }
    if (!have_nodes || !have_elements) throw FileError(file, "missing $Nodes or $Elements section");
    if (tets.empty()) throw FileError(file, "contains no tetrahedra (element type 4)");
    if (metadata) *metadata = find_metadata_comments(contents, "", file);
    return mesh_from_foreign_geometry(std::move(nodes.positions), std::move(tets), file);
}

void format_gmsh(const TetMesh& mesh, std::ostream& out, const VolumeMetadata& metadata) {
    const auto n_vertices = static_cast<int64_t>(mesh.vertex_count());
    const auto n_tets = static_cast<int64_t>(mesh.tet_count());
    std::string text;
    text.reserve(static_cast<size_t>(n_vertices) * 72 + static_cast<size_t>(n_tets) * 40 + 512);
    text += "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
    if (const std::string lines = metadata_comment_lines(metadata, ""); !lines.empty())
        text += "$Comments\n" + lines + "$EndComments\n";
    text += "$Entities\n0 0 0 1\n1";
    const auto box = bounding_box(mesh);
    for (const auto& corner : box)
        for (int k = 0; k < 3; ++k) {
            text += ' ';
            append_number(text, corner[k]);
        }
    text += " 0 0\n$EndEntities\n$Nodes\n";
    auto append_line = [&](std::initializer_list<int64_t> values) {
        bool first = true;
        for (const int64_t value : values) {
            if (!first) text += ' ';
            first = false;
            append_number(text, value);
        }
        text += '\n';
    };
    if (n_vertices > 0) {
        append_line({1, n_vertices, 1, n_vertices});
        append_line({3, 1, 0, n_vertices});
        for (int64_t v = 1; v <= n_vertices; ++v) append_line({v});
        for (const Eigen::Vector3d& p : mesh.positions) {
            append_number(text, p.x());
            text += ' ';
            append_number(text, p.y());
            text += ' ';
            append_number(text, p.z());
            text += '\n';
        }
    } else {
        append_line({0, 0, 0, 0});
    }
    text += "$EndNodes\n$Elements\n";
    if (n_tets > 0) {
        append_line({1, n_tets, 1, n_tets});
        append_line({3, 1, kGmshTetrahedron, n_tets});
        for (int64_t t = 0; t < n_tets; ++t) {
            const Tet& tet = mesh.tets[static_cast<size_t>(t)];
            append_line({t + 1, int64_t{tet[0]} + 1, int64_t{tet[1]} + 1, int64_t{tet[2]} + 1, int64_t{tet[3]} + 1});
        }
    } else {
        append_line({0, 0, 0, 0});
    }
    text += "$EndElements\n";
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

void write_gmsh(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata) {
    write_file_atomically(path, [&](std::ostream& out) { format_gmsh(mesh, out, metadata); });
}

TetMesh read_gmsh(const std::filesystem::path& path, VolumeMetadata* metadata) {
    return parse_gmsh(read_file_contents(path), path.string(), metadata);
}

}  // namespace waxwork
