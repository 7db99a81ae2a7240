#include "io/vtu_format.h"

#include "base/error.h"
#include "io/atomic_file.h"
#include "io/base64.h"
#include "io/file_contents.h"
#include "io/volume_checks.h"

#include <pugixml.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <charconv>
#include <cstring>
#include <optional>
#include <string_view>
#include <type_traits>
#include <utility>

namespace waxwork {
namespace {

// The binary encoding stores little-endian bytes; copying memory as is keeps reads and writes fast.
static_assert(std::endian::native == std::endian::little, "the .vtu reader and writer assume a little-endian host");

constexpr uint8_t kVtkTetra = 10;
// Indices are int32 in a TetMesh, so larger counts cannot be represented (and guard allocations).
constexpr uint64_t kMaxCount = uint64_t{1} << 31;

// ---------------------------------------------------------------------------------------------
// Writing. The XML skeleton is fixed ASCII text, so it is emitted directly; pugixml would only add a
// copy of the 60 MB of base64 text of a large volume.

template <class T>
constexpr const char* vtk_type_name() {
    if constexpr (std::is_same_v<T, double>) return "Float64";
    if constexpr (std::is_same_v<T, int32_t>) return "Int32";
    if constexpr (std::is_same_v<T, int64_t>) return "Int64";
    if constexpr (std::is_same_v<T, uint8_t>) return "UInt8";
}

template <class T>
void write_data_array(std::ostream& out, std::string_view indent, std::string_view name, size_t components,
                      const T* values, size_t value_count) {
    out << indent << "<DataArray type=\"" << vtk_type_name<T>() << "\" Name=\"" << name
        << "\" NumberOfComponents=\"" << components << "\" NumberOfTuples=\"" << value_count / components
        << "\" format=\"binary\">\n";
    // One base64 stream of [UInt64 byte count][data], as VTK writes uncompressed inline arrays. The
    // 8-byte header plus the first data byte make 9 bytes, a whole number of base64 groups, so the
    // rest of the data is encoded in place without copying it behind the header first.
    const uint64_t byte_count = value_count * sizeof(T);
    const auto* data = reinterpret_cast<const uint8_t*>(values);
    const size_t head_data = std::min<uint64_t>(byte_count, 1);
    uint8_t head[sizeof(uint64_t) + 1];
    std::memcpy(head, &byte_count, sizeof(uint64_t));
    if (head_data > 0) head[sizeof(uint64_t)] = data[0];
    std::string text;
    text.reserve(indent.size() + 3 + (byte_count + 12) / 3 * 4);
    text.append(indent);
    text.append("  ");
    append_base64(head, sizeof(uint64_t) + head_data, text);
    if (byte_count > head_data) append_base64(data + head_data, byte_count - head_data, text);
    text.push_back('\n');
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out << indent << "</DataArray>\n";
}

// ---------------------------------------------------------------------------------------------
// Reading.

enum class ScalarType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

std::optional<ScalarType> scalar_type_named(std::string_view name) {
    static constexpr std::pair<std::string_view, ScalarType> kTypes[] = {
        {"Int8", ScalarType::Int8},       {"UInt8", ScalarType::UInt8},     {"Int16", ScalarType::Int16},
        {"UInt16", ScalarType::UInt16},   {"Int32", ScalarType::Int32},     {"UInt32", ScalarType::UInt32},
        {"Int64", ScalarType::Int64},     {"UInt64", ScalarType::UInt64},   {"Float32", ScalarType::Float32},
        {"Float64", ScalarType::Float64}, {"Char", ScalarType::Int8},       {"UChar", ScalarType::UInt8}};
    for (const auto& [type_name, type] : kTypes)
        if (type_name == name) return type;
    return std::nullopt;
}

size_t scalar_size(ScalarType type) {
    switch (type) {
        case ScalarType::Int8:
        case ScalarType::UInt8: return 1;
        case ScalarType::Int16:
        case ScalarType::UInt16: return 2;
        case ScalarType::Int32:
        case ScalarType::UInt32:
        case ScalarType::Float32: return 4;
        case ScalarType::Int64:
        case ScalarType::UInt64:
        case ScalarType::Float64: return 8;
    }
    return 1;
}

// Converts one stored value to the in-memory type; false when it does not fit exactly enough
// (out-of-range integers, floating-point data where integers are required).
template <class Target, class Source>
bool convert_value(Source source, Target& target) {
    if constexpr (std::is_floating_point_v<Target>) {
        target = static_cast<Target>(source);
        return true;
    } else if constexpr (std::is_floating_point_v<Source>) {
        return false;
    } else {
        if (!std::in_range<Target>(source)) return false;
        target = static_cast<Target>(source);
        return true;
    }
}

template <class Target, class Source>
bool convert_bytes(const uint8_t* bytes, size_t count, std::vector<Target>& out) {
    out.resize(count);
    if constexpr (std::is_same_v<Target, Source>) {
        if (count > 0) std::memcpy(out.data(), bytes, count * sizeof(Source));
        return true;
    } else {
        for (size_t i = 0; i < count; ++i) {
            Source value;
            std::memcpy(&value, bytes + i * sizeof(Source), sizeof(Source));
            if (!convert_value(value, out[i])) return false;
        }
        return true;
    }
}

template <class Target>
bool convert_bytes(ScalarType type, const uint8_t* bytes, size_t count, std::vector<Target>& out) {
    switch (type) {
        case ScalarType::Int8: return convert_bytes<Target, int8_t>(bytes, count, out);
        case ScalarType::UInt8: return convert_bytes<Target, uint8_t>(bytes, count, out);
        case ScalarType::Int16: return convert_bytes<Target, int16_t>(bytes, count, out);
        case ScalarType::UInt16: return convert_bytes<Target, uint16_t>(bytes, count, out);
        case ScalarType::Int32: return convert_bytes<Target, int32_t>(bytes, count, out);
        case ScalarType::UInt32: return convert_bytes<Target, uint32_t>(bytes, count, out);
        case ScalarType::Int64: return convert_bytes<Target, int64_t>(bytes, count, out);
        case ScalarType::UInt64: return convert_bytes<Target, uint64_t>(bytes, count, out);
        case ScalarType::Float32: return convert_bytes<Target, float>(bytes, count, out);
        case ScalarType::Float64: return convert_bytes<Target, double>(bytes, count, out);
    }
    return false;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

class VtuReader {
public:
    VtuReader(std::string file, size_t header_size) : file_(std::move(file)), header_size_(header_size) {}

    [[noreturn]] void fail(const std::string& problem) const { throw FileError(file_, problem); }

    // The values of `node`, which must have `components` components and, when given, `tuples` tuples.
    template <class T>
    std::vector<T> read(const pugi::xml_node& node, size_t components, std::optional<size_t> tuples) const {
        const std::string name = std::string("DataArray '") + node.attribute("Name").value() + "'";
        const auto type = scalar_type_named(node.attribute("type").value());
        if (!type) fail(name + " has unsupported type '" + node.attribute("type").value() + "'");
        const uint64_t stored_components = count_attribute(node, "NumberOfComponents", name).value_or(1);
        if (stored_components != components) {
            fail(name + " has " + std::to_string(stored_components) + " components, expected " +
                 std::to_string(components));
        }
        if (const auto stored_tuples = count_attribute(node, "NumberOfTuples", name)) {
            if (tuples && *stored_tuples != *tuples) {
                fail(name + " has " + std::to_string(*stored_tuples) + " tuples, expected " + std::to_string(*tuples));
            }
            tuples = *stored_tuples;
        }
        const std::string_view format = node.attribute("format").value();
        const std::string_view text = node.child_value();
        std::vector<T> values;
        if (format == "binary") {
            values = read_binary<T>(*type, text, name);
        } else if (format == "ascii") {
            values = read_ascii<T>(text, name, tuples ? *tuples * components : 0);
        } else if (format == "appended") {
            fail(name + " uses appended data, which is not supported (save with inline binary or ascii data)");
        } else {
            fail(name + " has unknown format '" + std::string(format) + "'");
        }
        if (values.size() % components != 0 || (tuples && values.size() != *tuples * components)) {
            fail(name + " holds " + std::to_string(values.size()) + " values, expected " +
                 (tuples ? std::to_string(*tuples * components) : "a multiple of " + std::to_string(components)));
        }
        return values;
    }

    std::optional<uint64_t> count_attribute(const pugi::xml_node& node, const char* attribute,
                                            const std::string& owner) const {
        const pugi::xml_attribute value = node.attribute(attribute);
        if (!value) return std::nullopt;
        return parse_count(value.value(), owner + " attribute " + attribute);
    }

    uint64_t parse_count(std::string_view text, const std::string& what) const {
        uint64_t count = 0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), count);
        if (error != std::errc() || end != text.data() + text.size()) {
            fail(what + " is not a count: '" + std::string(text.substr(0, 32)) + "'");
        }
        if (count >= kMaxCount) fail(what + " is too large (" + std::to_string(count) + ")");
        return count;
    }

private:
    template <class T>
    std::vector<T> read_binary(ScalarType type, std::string_view text, const std::string& name) const {
        const std::optional<std::vector<uint8_t>> decoded = decode_base64(text);
        if (!decoded) fail("invalid or truncated base64 data in " + name);
        if (decoded->size() < header_size_) fail("truncated base64 data in " + name + " (no size header)");
        uint64_t byte_count = 0;
        if (header_size_ == 4) {
            uint32_t small = 0;
            std::memcpy(&small, decoded->data(), 4);
            byte_count = small;
        } else {
            std::memcpy(&byte_count, decoded->data(), 8);
        }
        const size_t present = decoded->size() - header_size_;
        if (byte_count > present) {
            fail("truncated base64 data in " + name + " (" + std::to_string(byte_count) + " bytes announced, " +
                 std::to_string(present) + " present)");
        }
        if (byte_count < present) {
            fail(name + " has " + std::to_string(present - byte_count) + " bytes of data beyond its size header");
        }
        const size_t size = scalar_size(type);
        if (byte_count % size != 0) fail(name + " size " + std::to_string(byte_count) + " is not a whole number of values");
        std::vector<T> values;
        if (!convert_bytes(type, decoded->data() + header_size_, byte_count / size, values)) {
            fail(name + " has values that do not fit the expected type");
        }
        return values;
    }

    template <class T>
    std::vector<T> read_ascii(std::string_view text, const std::string& name, size_t expected) const {
        std::vector<T> values;
        values.reserve(std::min(expected, text.size() / 2 + 1));
        size_t i = 0;
        while (true) {
            while (i < text.size() && is_space(text[i])) ++i;
            if (i >= text.size()) break;
            size_t end = i;
            while (end < text.size() && !is_space(text[end])) ++end;
            const std::string_view token = text.substr(i, end - i);
            i = end;
            T value{};
            bool ok = false;
            if constexpr (std::is_floating_point_v<T>) {
                const auto [stop, error] = std::from_chars(token.data(), token.data() + token.size(), value);
                ok = error == std::errc() && stop == token.data() + token.size();
            } else {
                int64_t wide = 0;
                const auto [stop, error] = std::from_chars(token.data(), token.data() + token.size(), wide);
                ok = error == std::errc() && stop == token.data() + token.size() && convert_value(wide, value);
            }
            if (!ok) fail(name + " has an invalid value '" + std::string(token.substr(0, 32)) + "'");
            values.push_back(value);
        }
        return values;
    }

    std::string file_;
    size_t header_size_;
};

[[noreturn]] void fail_file(const std::string& file, const std::string& problem) {
    throw FileError(file, problem);
}

// The DataArray of `parent` called `name`, or a null node. Two arrays of one name are refused: which
// one a program reads is arbitrary, so the file is ambiguous.
pugi::xml_node find_array(const pugi::xml_node& parent, std::string_view name, const std::string& file) {
    pugi::xml_node found;
    for (const pugi::xml_node& array : parent.children("DataArray")) {
        if (name != array.attribute("Name").value()) continue;
        if (found) fail_file(file, std::string(parent.name()) + " has two DataArrays named '" + std::string(name) + "'");
        found = array;
    }
    return found;
}

// VTK cell types that fill a volume (linear and higher-order hexahedra, wedges, pyramids, polyhedra,
// quadratic tetrahedra): a file holding one describes a volume Waxwork would read only in part.
bool is_volume_cell_type(uint8_t type) {
    switch (type) {
        case 11: case 12: case 13: case 14: case 15: case 16:  // voxel .. hexagonal prism
        case 24: case 25: case 26: case 27: case 29: case 32: case 33:  // quadratic 3D cells
        case 42:  // polyhedron
        case 71: case 72: case 73: case 74:  // Lagrange 3D cells
            return true;
        default:
            return false;
    }
}

}  // namespace

void format_vtu(const TetMesh& mesh, std::ostream& out, const VolumeMetadata& metadata) {
    const size_t n_tets = mesh.tet_count();
    out << "<?xml version=\"1.0\"?>\n"
           "<!-- Waxwork volume: see io/vtu_format.h for the layout. -->\n"
           "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
           "header_type=\"UInt64\">\n"
           "  <UnstructuredGrid>\n"
           "    <FieldData>\n";
    const int32_t version = kVtuFormatVersion;
    write_data_array(out, "      ", "waxwork_format_version", 1, &version, 1);
    std::vector<double> transforms;
    transforms.reserve(mesh.piece_transforms.size() * 12);
    for (const RigidTransform& transform : mesh.piece_transforms) {
        for (int row = 0; row < 3; ++row)
            for (int column = 0; column < 3; ++column) transforms.push_back(transform.rotation(row, column));
        for (int i = 0; i < 3; ++i) transforms.push_back(transform.translation[i]);
    }
    write_data_array(out, "      ", "piece_transforms", 12, transforms.data(), transforms.size());
    if (metadata.mm_per_unit) write_data_array(out, "      ", "mm_per_unit", 1, &*metadata.mm_per_unit, 1);
    out << "    </FieldData>\n"
        << "    <Piece NumberOfPoints=\"" << mesh.vertex_count() << "\" NumberOfCells=\"" << n_tets << "\">\n"
        << "      <Points>\n";
    static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "positions must be packed");
    write_data_array(out, "        ", "Points", 3, mesh.positions.empty() ? nullptr : mesh.positions[0].data(),
                     3 * mesh.vertex_count());
    out << "      </Points>\n"
        << "      <Cells>\n";
    static_assert(sizeof(Tet) == 4 * sizeof(int32_t), "tets must be packed");
    write_data_array(out, "        ", "connectivity", 1, mesh.tets.empty() ? nullptr : mesh.tets[0].data(),
                     4 * n_tets);
    std::vector<int64_t> offsets(n_tets);
    for (size_t t = 0; t < n_tets; ++t) offsets[t] = 4 * static_cast<int64_t>(t + 1);
    write_data_array(out, "        ", "offsets", 1, offsets.data(), n_tets);
    const std::vector<uint8_t> types(n_tets, kVtkTetra);
    write_data_array(out, "        ", "types", 1, types.data(), n_tets);
    out << "      </Cells>\n"
        << "      <CellData>\n";
    if (mesh.has_materials()) {
        std::vector<double> mua, musp, eta;
        mua.reserve(3 * n_tets);
        musp.reserve(3 * n_tets);
        eta.reserve(n_tets);
        for (const TetMaterial& material : mesh.materials) {
            mua.insert(mua.end(), material.mua.begin(), material.mua.end());
            musp.insert(musp.end(), material.musp.begin(), material.musp.end());
            eta.push_back(material.eta);
        }
        write_data_array(out, "        ", "mua", 3, mua.data(), mua.size());
        write_data_array(out, "        ", "musp", 3, musp.data(), musp.size());
        write_data_array(out, "        ", "eta", 1, eta.data(), eta.size());
    }
    write_data_array(out, "        ", "original_id", 1, mesh.original_ids.data(), mesh.original_ids.size());
    write_data_array(out, "        ", "piece", 1, mesh.piece_ids.data(), mesh.piece_ids.size());
    out << "      </CellData>\n"
           "    </Piece>\n"
           "  </UnstructuredGrid>\n"
           "</VTKFile>\n";
}

TetMesh parse_vtu(std::string contents, const std::string& file, VolumeMetadata* metadata) {
    if (metadata) *metadata = {};
    pugi::xml_document document;
    const pugi::xml_parse_result parsed =
        document.load_buffer_inplace(contents.data(), contents.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!parsed) {
        fail_file(file, std::string("not valid XML (") + parsed.description() + " at byte " + std::to_string(parsed.offset) +
             ")");
    }
    const pugi::xml_node root = document.child("VTKFile");
    if (!root) fail_file(file, "not a VTK XML file (no VTKFile element)");
    if (std::string_view(root.attribute("type").value()) != "UnstructuredGrid") {
        fail_file(file, std::string("VTK file type '") + root.attribute("type").value() + "' is not UnstructuredGrid");
    }
    const std::string_view byte_order = root.attribute("byte_order").value();
    if (!byte_order.empty() && byte_order != "LittleEndian") {
        fail_file(file, "byte_order '" + std::string(byte_order) + "' is not supported (only LittleEndian)");
    }
    const std::string_view header_type = root.attribute("header_type").value();
    size_t header_size = 4;  // VTK's default before header_type existed
    if (header_type == "UInt64") {
        header_size = 8;
    } else if (!header_type.empty() && header_type != "UInt32") {
        fail_file(file, "header_type '" + std::string(header_type) + "' is not supported");
    }
    if (root.attribute("compressor")) {
        fail_file(file, std::string("compressed data (") + root.attribute("compressor").value() +
             ") is not supported; save the file uncompressed");
    }
    const pugi::xml_node grid = root.child("UnstructuredGrid");
    if (!grid) fail_file(file, "no UnstructuredGrid element");
    const auto pieces = grid.children("Piece");
    const auto piece_count = std::distance(pieces.begin(), pieces.end());
    if (piece_count != 1) fail_file(file, "has " + std::to_string(piece_count) + " Piece elements; exactly one is supported");
    const pugi::xml_node piece = grid.child("Piece");

    const VtuReader reader(file, header_size);
    const uint64_t n_points = reader.parse_count(piece.attribute("NumberOfPoints").value(), "NumberOfPoints");
    const uint64_t n_cells = reader.parse_count(piece.attribute("NumberOfCells").value(), "NumberOfCells");

    std::vector<double> coordinates;
    const auto point_arrays = piece.child("Points").children("DataArray");
    if (std::distance(point_arrays.begin(), point_arrays.end()) > 1) fail_file(file, "Points has more than one DataArray");
    if (const pugi::xml_node points = piece.child("Points").child("DataArray")) {
        coordinates = reader.read<double>(points, 3, n_points);
    } else if (n_points > 0) {
        fail_file(file, "no Points DataArray");
    }
    for (size_t i = 0; i < coordinates.size(); ++i)
        if (!std::isfinite(coordinates[i])) fail_file(file, "point " + std::to_string(i / 3) + " has a non-finite coordinate");
    std::vector<Eigen::Vector3d> positions(n_points);
    for (size_t v = 0; v < n_points; ++v)
        positions[v] = Eigen::Vector3d(coordinates[3 * v], coordinates[3 * v + 1], coordinates[3 * v + 2]);
    coordinates = {};

    const pugi::xml_node cells = piece.child("Cells");
    const pugi::xml_node offsets_node = find_array(cells, "offsets", file);
    const pugi::xml_node connectivity_node = find_array(cells, "connectivity", file);
    const pugi::xml_node types_node = find_array(cells, "types", file);
    if (n_cells > 0 && (!offsets_node || !connectivity_node || !types_node)) {
        fail_file(file, "Cells needs DataArrays 'connectivity', 'offsets' and 'types'");
    }
    std::vector<int64_t> offsets, connectivity;
    std::vector<uint8_t> types;
    if (n_cells > 0) {
        offsets = reader.read<int64_t>(offsets_node, 1, n_cells);
        types = reader.read<uint8_t>(types_node, 1, n_cells);
        int64_t previous = 0;
        for (size_t c = 0; c < n_cells; ++c) {
            if (offsets[c] < previous) fail_file(file, "DataArray 'offsets' decreases at cell " + std::to_string(c));
            previous = offsets[c];
        }
        if (static_cast<uint64_t>(offsets.back()) > 8 * kMaxCount) fail_file(file, "DataArray 'offsets' is absurdly large");
        connectivity = reader.read<int64_t>(connectivity_node, 1, static_cast<size_t>(offsets.back()));
        for (size_t i = 0; i < connectivity.size(); ++i) {
            if (connectivity[i] < 0 || static_cast<uint64_t>(connectivity[i]) >= n_points) {
                const size_t cell = static_cast<size_t>(
                    std::upper_bound(offsets.begin(), offsets.end(), static_cast<int64_t>(i)) - offsets.begin());
                fail_file(file, "cell " + std::to_string(cell) + " references point " + std::to_string(connectivity[i]) +
                     " which does not exist (" + std::to_string(n_points) + " points)");
            }
        }
    }
    auto cell_points = [&](size_t c) { return offsets[c] - (c == 0 ? 0 : offsets[c - 1]); };
    auto cell_is_tet = [&](size_t c) { return types[c] == kVtkTetra && cell_points(c) == 4; };
    // Why a cell is not a tetrahedron (read only where it must be one).
    auto not_a_tet = [&](size_t c) {
        const std::string cell = "cell " + std::to_string(c);
        if (types[c] == kVtkTetra)
            return cell + " is a tetrahedron (VTK type 10) with " + std::to_string(cell_points(c)) +
                   " points in 'offsets'; a tetrahedron has 4";
        return cell + " is not a tetrahedron (VTK type " + std::to_string(types[c]) + ")";
    };

    const pugi::xml_node field_data = grid.child("FieldData");
    const pugi::xml_node version_node = find_array(field_data, "waxwork_format_version", file);
    if (!version_node) {
        // A file with Waxwork's own arrays but no version is a damaged Waxwork file, not another
        // program's: reading its geometry alone would drop its materials and pieces silently.
        for (const char* name : {"piece", "original_id", "mua"})
            if (find_array(piece.child("CellData"), name, file))
                fail_file(file, std::string("has Waxwork's CellData '") + name +
                                    "' but no FieldData 'waxwork_format_version' (a damaged Waxwork volume?)");
        if (find_array(field_data, "piece_transforms", file))
            fail_file(file, "has Waxwork's FieldData 'piece_transforms' but no 'waxwork_format_version' "
                            "(a damaged Waxwork volume?)");
        // A .vtu from another program: geometry of its tetrahedra only. Surface and line cells are
        // dropped (they bound or annotate the volume); other volume cells are refused, since dropping
        // them would drop part of the volume.
        std::vector<Tet> tets;
        for (size_t c = 0; c < n_cells; ++c) {
            if (is_volume_cell_type(types[c]) || (types[c] == kVtkTetra && !cell_is_tet(c)))
                fail_file(file, not_a_tet(c) + "; Waxwork reads volumes of linear tetrahedra only");
            if (!cell_is_tet(c)) continue;
            const size_t begin = static_cast<size_t>(offsets[c] - 4);
            tets.push_back({static_cast<int32_t>(connectivity[begin]), static_cast<int32_t>(connectivity[begin + 1]),
                            static_cast<int32_t>(connectivity[begin + 2]),
                            static_cast<int32_t>(connectivity[begin + 3])});
        }
        if (tets.empty()) fail_file(file, "contains no tetrahedra");
        return mesh_from_foreign_geometry(std::move(positions), std::move(tets), file);
    }

    const std::vector<int32_t> version = reader.read<int32_t>(version_node, 1, 1);
    if (version[0] != kVtuFormatVersion) {
        fail_file(file, "unsupported waxwork_format_version " + std::to_string(version[0]) + " (this build reads version " +
             std::to_string(kVtuFormatVersion) + ")");
    }
    TetMesh mesh;
    mesh.positions = std::move(positions);
    mesh.tets.resize(n_cells);
    for (size_t c = 0; c < n_cells; ++c) {
        if (!cell_is_tet(c)) fail_file(file, not_a_tet(c));
        const size_t begin = static_cast<size_t>(offsets[c] - 4);
        for (int k = 0; k < 4; ++k) mesh.tets[c][k] = static_cast<int32_t>(connectivity[begin + k]);
    }
    connectivity = {};

    const pugi::xml_node transforms_node = find_array(field_data, "piece_transforms", file);
    if (!transforms_node) fail_file(file, "missing FieldData array 'piece_transforms'");
    const std::vector<double> transforms = reader.read<double>(transforms_node, 12, std::nullopt);
    mesh.piece_transforms.resize(transforms.size() / 12);
    for (size_t p = 0; p < mesh.piece_transforms.size(); ++p) {
        const double* x = transforms.data() + 12 * p;
        for (int row = 0; row < 3; ++row)
            for (int column = 0; column < 3; ++column) mesh.piece_transforms[p].rotation(row, column) = x[3 * row + column];
        mesh.piece_transforms[p].translation = Eigen::Vector3d(x[9], x[10], x[11]);
    }

    VolumeMetadata stored;
    if (const pugi::xml_node scale_node = find_array(field_data, "mm_per_unit", file))
        stored.mm_per_unit = reader.read<double>(scale_node, 1, 1)[0];
    check_metadata(stored, file);
    if (metadata) *metadata = stored;

    const pugi::xml_node cell_data = piece.child("CellData");
    const pugi::xml_node mua_node = find_array(cell_data, "mua", file);
    const pugi::xml_node musp_node = find_array(cell_data, "musp", file);
    const pugi::xml_node eta_node = find_array(cell_data, "eta", file);
    const int material_arrays = (mua_node ? 1 : 0) + (musp_node ? 1 : 0) + (eta_node ? 1 : 0);
    if (material_arrays != 0 && material_arrays != 3) {
        fail_file(file, "CellData has only some of the material arrays 'mua', 'musp', 'eta'");
    }
    if (material_arrays == 3) {
        const std::vector<double> mua = reader.read<double>(mua_node, 3, n_cells);
        const std::vector<double> musp = reader.read<double>(musp_node, 3, n_cells);
        const std::vector<double> eta = reader.read<double>(eta_node, 1, n_cells);
        mesh.materials.resize(n_cells);
        for (size_t t = 0; t < n_cells; ++t) {
            TetMaterial& material = mesh.materials[t];
            for (int c = 0; c < 3; ++c) {
                material.mua[c] = mua[3 * t + c];
                material.musp[c] = musp[3 * t + c];
            }
            material.eta = eta[t];
        }
    }
    const pugi::xml_node original_node = find_array(cell_data, "original_id", file);
    const pugi::xml_node piece_node = find_array(cell_data, "piece", file);
    if (!original_node || !piece_node) fail_file(file, "CellData needs arrays 'original_id' and 'piece'");
    mesh.original_ids = reader.read<int32_t>(original_node, 1, n_cells);
    mesh.piece_ids = reader.read<int32_t>(piece_node, 1, n_cells);

    check_volume(mesh, file);
    return mesh;
}

void write_vtu(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata) {
    write_file_atomically(path, [&](std::ostream& out) { format_vtu(mesh, out, metadata); });
}

TetMesh read_vtu(const std::filesystem::path& path, VolumeMetadata* metadata) {
    return parse_vtu(read_file_contents(path), path.string(), metadata);
}

}  // namespace waxwork
