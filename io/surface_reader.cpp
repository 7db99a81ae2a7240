#include "io/surface_reader.h"

#include "io/file_extension.h"
#include "tetops/tet_mesh.h"

#include "base/error.h"
#include "base/progress.h"

#include <CGAL/IO/OFF.h>
#include <CGAL/Simple_cartesian.h>
#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/ImporterT.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string_view>

namespace waxwork {
namespace {

struct DoublePrecisionTraits : OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
    using Normal = OpenMesh::Vec3d;
};
using ReaderMesh = OpenMesh::PolyMesh_ArrayKernelT<DoublePrecisionTraits>;

// Records the faces exactly as the reader passes them. OpenMesh's own importer refuses faces that
// repeat a vertex and, for faces that would make an edge or vertex non-manifold, silently adds copies
// of their vertices; either would hide the defects that validation must see. The mesh is still built
// (readers may query it), but the soup comes from what was recorded.
class SoupImporter : public OpenMesh::IO::ImporterT<ReaderMesh> {
public:
    using Base = OpenMesh::IO::ImporterT<ReaderMesh>;
    explicit SoupImporter(ReaderMesh& mesh) : Base(mesh), mesh_(mesh) {}

    OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3f& p) override { return record(Base::add_vertex(p)); }
    OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3d& p) override { return record(Base::add_vertex(p)); }
    OpenMesh::VertexHandle add_vertex() override { return record(Base::add_vertex()); }

    OpenMesh::FaceHandle add_face(const VHandles& handles) override {
        std::vector<int32_t> face;
        face.reserve(handles.size());
        bool usable = handles.size() >= 3;
        for (auto h : handles) {
            const int i = h.idx();
            const bool known = i >= 0 && static_cast<size_t>(i) < soup_index_.size() && soup_index_[i] >= 0;
            face.push_back(known ? soup_index_[i] : -1);
            usable = usable && known;
        }
        faces_.push_back(face);
        for (size_t a = 0; a < handles.size() && usable; ++a)
            for (size_t b = a + 1; b < handles.size(); ++b) usable = usable && handles[a] != handles[b];
        // Only faces OpenMesh can represent go to its mesh; the others would just produce console noise.
        return usable ? Base::add_face(handles) : OpenMesh::FaceHandle();
    }

    // The recorded vertices with their final positions (a reader may set them after creating them).
    std::vector<Eigen::Vector3d> points() const {
        std::vector<Eigen::Vector3d> result;
        result.reserve(vertices_.size());
        for (auto v : vertices_) {
            const auto& p = mesh_.point(v);
            result.emplace_back(p[0], p[1], p[2]);
        }
        return result;
    }
    const std::vector<std::vector<int32_t>>& faces() const { return faces_; }

private:
    OpenMesh::VertexHandle record(OpenMesh::VertexHandle v) {
        if (v.idx() >= 0) {
            if (static_cast<size_t>(v.idx()) >= soup_index_.size()) soup_index_.resize(v.idx() + 1, -1);
            soup_index_[v.idx()] = static_cast<int32_t>(vertices_.size());
            vertices_.push_back(v);
        }
        return v;
    }

    ReaderMesh& mesh_;
    std::vector<OpenMesh::VertexHandle> vertices_;  // in the order the reader created them
    std::vector<int32_t> soup_index_;               // OpenMesh vertex index -> soup index, -1 for copies
    std::vector<std::vector<int32_t>> faces_;
};

// OpenMesh prints to its own global streams (omerr, omlog, omout), connected to the standard streams.
// On the first read they are disconnected from those for good and omerr is connected to a buffer, so
// that a problem can be reported in the FileError instead of on the console. The redirection is made
// once per process, not per read, because OpenMesh's mostream::disconnect drops the target wrapper
// that connect allocated (a leak per read, found with LeakSanitizer). The streams are global, hence the
// mutex serialising all reads (OpenMesh's IOManager is a global singleton too).
class OpenMeshOutputCapture {
public:
    OpenMeshOutputCapture() : errors_(redirected_errors()) {
        ::omerr().enable();
        errors_.str("");
        errors_.clear();
    }
    OpenMeshOutputCapture(const OpenMeshOutputCapture&) = delete;
    OpenMeshOutputCapture& operator=(const OpenMeshOutputCapture&) = delete;

    // The first line OpenMesh complained with during this read, or "".
    std::string first_error() {
        ::omerr().flush();
        std::string line;
        std::istringstream in(errors_.str());
        while (std::getline(in, line))
            if (line.find_first_not_of(" \t\r") != std::string::npos) return line;
        return {};
    }

private:
    static std::ostringstream& redirected_errors() {
        // Never destroyed: OpenMesh's static streams keep a reference to it until exit.
        static std::ostringstream* const buffer = [] {
            for (OpenMesh::mostream* stream : {&::omerr(), &::omlog(), &::omout()}) {
                stream->disconnect(std::cerr);
                stream->disconnect(std::clog);
                stream->disconnect(std::cout);
            }
            auto* errors = new std::ostringstream;
            ::omerr().connect(*errors);
            return errors;
        }();
        return *buffer;
    }

    std::ostringstream& errors_;
};

std::mutex& reader_mutex() {
    static std::mutex mutex;
    return mutex;
}

std::string format_name(const std::string& ext) {
    std::string name = ext.substr(1);
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::toupper(c)); });
    return name;
}

// OpenMesh's ascii readers skip a vertex whose coordinates do not parse ("nan", "1e400", "x") and
// carry on, so every later index is off by one and the error that surfaces ("face 7 refers to a
// vertex that does not exist", or a bogus open surface) hides the real problem. The vertex records
// are therefore checked here first: the first three numbers of each must be finite doubles.
std::string_view first_token(std::string_view line, size_t& end) {
    size_t begin = 0;
    while (begin < line.size() && std::isspace(static_cast<unsigned char>(line[begin]))) ++begin;
    end = begin;
    while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end]))) ++end;
    return line.substr(begin, end - begin);
}

// One coordinate; throws FileError naming the line and the token.
void check_coordinate(const std::filesystem::path& path, size_t line_number, std::string_view token) {
    const std::string where = "line " + std::to_string(line_number) + ": vertex coordinate '" + std::string(token) + "' ";
    double value = 0;
    // from_chars does not take a leading '+', which some exporters write.
    const std::string_view digits = !token.empty() && token.front() == '+' ? token.substr(1) : token;
    const auto [ptr, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error == std::errc::result_out_of_range) throw FileError(path.string(), where + "is out of range");
    if (error != std::errc() || ptr != digits.data() + digits.size())
        throw FileError(path.string(), where + "is not a number");
    if (!std::isfinite(value)) throw FileError(path.string(), where + "is not finite");
}

// The three coordinates at the start of `rest`.
void check_coordinates(const std::filesystem::path& path, size_t line_number, std::string_view rest) {
    for (int axis = 0; axis < 3; ++axis) {
        size_t end = 0;
        const std::string_view token = first_token(rest, end);
        if (token.empty() || token.front() == '#')
            throw FileError(path.string(), "line " + std::to_string(line_number) +
                                               ": vertex coordinates: expected 3 numbers, found " + std::to_string(axis));
        check_coordinate(path, line_number, token);
        rest = rest.substr(end);
    }
}

// Every line whose first word is `keyword` ("v" in OBJ, "vertex" in ascii STL) holds a vertex.
void check_vertex_lines(const std::filesystem::path& path, std::string_view text, std::string_view keyword) {
    size_t line_number = 0;
    for (size_t start = 0; start < text.size();) {
        const size_t newline = std::min(text.find('\n', start), text.size());
        const std::string_view line = text.substr(start, newline - start);
        ++line_number;
        size_t end = 0;
        if (first_token(line, end) == keyword) check_coordinates(path, line_number, line.substr(end));
        start = newline + 1;
    }
}

// A binary STL's 50-byte records hold a normal and three vertices as little-endian floats.
void check_binary_stl_coordinates(const std::filesystem::path& path, std::string_view bytes, uint32_t count) {
    for (uint32_t t = 0; t < count; ++t) {
        for (int k = 0; k < 9; ++k) {
            float value = 0;
            std::memcpy(&value, bytes.data() + 84 + 50 * static_cast<size_t>(t) + 12 + 4 * k, sizeof value);
            if (!std::isfinite(value))
                throw FileError(path.string(), "triangle " + std::to_string(t) + ": vertex " + std::to_string(k / 3) +
                                                   " has a non-finite coordinate");
        }
    }
}

// OpenMesh trusts the element counts in OFF and PLY headers: a corrupt count makes it reserve memory
// for it, and in ascii files a truncated body makes it loop on a failed stream and invent elements
// from stale values (faces like 0 0 0), which would pass for a smaller mesh. So the header is checked
// against the body before OpenMesh reads it: every element needs at least two bytes, and an ascii
// body must hold enough numbers (OFF: 3 per vertex, 4 per face) or lines (PLY: one per element).
// Binary PLY needs no such check: OpenMesh reports its end of file itself.
std::string read_all(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void check_count_fits(const std::filesystem::path& path, const std::string& what, unsigned long long count,
                      std::uintmax_t size) {
    if (count > size / 2)
        throw FileError(path.string(), "header declares " + std::to_string(count) + " " + what +
                                           " but the file has only " + std::to_string(size) + " bytes");
}

unsigned long long parse_count(const std::filesystem::path& path, const std::string& token) {
    if (token.empty() || token.find_first_not_of("0123456789") != std::string::npos)
        throw FileError(path.string(), "malformed header: '" + token.substr(0, 40) + (token.size() > 40 ? "..." : "") +
                                           "' is not an element count");
    try {
        return std::stoull(token);
    } catch (const std::out_of_range&) {
        throw FileError(path.string(), "malformed header: element count " + token + " is out of range");
    }
}

void check_off_body(const std::filesystem::path& path, std::uintmax_t size) {
    const std::string text = read_all(path);
    // Whitespace-separated tokens with '#' comments removed; only counted past the header.
    std::vector<std::string_view> header;
    size_t body_tokens = 0;
    size_t counts_end = 0;  // just past "ne", the last of the header's counts
    bool in_comment = false;
    for (size_t i = 0; i < text.size();) {
        const char c = text[i];
        if (c == '\n') in_comment = false;
        if (in_comment || std::isspace(static_cast<unsigned char>(c))) {
            ++i;
            continue;
        }
        if (c == '#') {
            in_comment = true;
            continue;
        }
        size_t j = i;
        while (j < text.size() && !std::isspace(static_cast<unsigned char>(text[j])) && text[j] != '#') ++j;
        if (header.size() < 5) {
            header.emplace_back(text.data() + i, j - i);
            if (header.size() == 4) counts_end = j;
        } else
            ++body_tokens;
        i = j;
    }
    // Only the plain ascii layout "[ST][C][N]OFF nv nf ne" is checked; other variants go to OpenMesh
    // as they are.
    if (header.size() < 4 || header[0].find("OFF") == std::string_view::npos || header[0].find('n') != std::string_view::npos ||
        header[0].find('4') != std::string_view::npos || header[1] == "BINARY")
        return;
    const auto vertices = parse_count(path, std::string(header[1]));
    const auto faces = parse_count(path, std::string(header[2]));
    check_count_fits(path, "vertices", vertices, size);
    check_count_fits(path, "faces", faces, size);
    body_tokens += header.size() - 4;  // tokens after "OFF nv nf ne" that were kept as header
    if (body_tokens < 3 * vertices + 4 * faces)
        throw FileError(path.string(), "truncated: the header declares " + std::to_string(vertices) +
                                           " vertices and " + std::to_string(faces) +
                                           " faces but the file ends before them");
    // One record per line after the counts: vertices (a [C][N]OFF vertex carries colour or normal
    // values after its three coordinates), then faces "k i_1 ... i_k" (maybe followed by a colour).
    size_t line_number = 1 + static_cast<size_t>(std::count(text.begin(), text.begin() + counts_end, '\n'));
    size_t start = std::min(text.find('\n', counts_end), text.size());
    for (unsigned long long record = 0; record < vertices + faces && start < text.size();) {
        ++start;
        ++line_number;
        const size_t newline = std::min(text.find('\n', start), text.size());
        std::string_view line = std::string_view(text).substr(start, newline - start);
        start = newline;
        line = line.substr(0, std::min(line.find('#'), line.size()));
        size_t end = 0;
        if (first_token(line, end).empty()) continue;
        if (record++ < vertices) {
            check_coordinates(path, line_number, line);
            continue;
        }
        const unsigned long long face = record - 1 - vertices;
        const std::string where = "line " + std::to_string(line_number) + ": face " + std::to_string(face);
        unsigned long long corners = 0;
        for (long long k = -1; k < static_cast<long long>(corners); ++k) {
            const std::string_view token = first_token(line, end);
            line = line.substr(end);
            unsigned long long value = 0;
            const auto [ptr, error] = std::from_chars(token.data(), token.data() + token.size(), value);
            if (token.empty() && k >= 0)
                throw FileError(path.string(), where + ": " + std::to_string(k) + " vertex indices where its count says " +
                                                   std::to_string(corners));
            if (error != std::errc() || ptr != token.data() + token.size())
                throw FileError(path.string(), where + ": '" + std::string(token) + "' is not " +
                                                   (k < 0 ? "a vertex count" : "a vertex index"));
            if (k < 0) {
                corners = value;
                // Each index takes at least two characters: a larger count cannot be on this line.
                if (corners > line.size())
                    throw FileError(path.string(), where + ": a count of " + std::to_string(corners) +
                                                       " vertex indices on a line that cannot hold them");
            } else if (value >= vertices) {
                throw FileError(path.string(), where + " refers to vertex " + std::to_string(value) +
                                                   " but the file has " + std::to_string(vertices) + " vertices");
            }
        }
    }
}

[[noreturn]] void fail_ply_header(const std::filesystem::path& path, int line_number, const std::string& why) {
    throw FileError(path.string(), "PLY header line " + std::to_string(line_number) + ": " + why);
}

bool is_ply_scalar_type(const std::string& type) {
    static const std::array<const char*, 16> types = {"char",  "uchar",  "short", "ushort",  "int",    "uint",
                                                      "float", "double", "int8",  "uint8",   "int16",  "uint16",
                                                      "int32", "uint32", "float32", "float64"};
    return std::find(types.begin(), types.end(), type) != types.end();
}

// What OpenMesh's PLY reader does not survive, refused with the line (line 1 is "ply"): a format
// other than ascii / binary_little_endian / binary_big_endian 1.0 (a version that is not a number
// made it loop for ever), a property before any element (it crashed), types PLY does not define,
// and vertex coordinates that are not float or double (it printed a line per value and read zeros).
void check_ply_header_line(const std::filesystem::path& path, int line_number, const std::string& keyword,
                           const std::string& first, const std::string& second, const std::string& third,
                           bool after_an_element) {
    const auto fail = [&](const std::string& why) { fail_ply_header(path, line_number, why); };
    if (line_number == 1) {
        if (keyword != "ply") fail("the file does not start with 'ply'");
        return;
    }
    if (keyword == "format") {
        if (first != "ascii" && first != "binary_little_endian" && first != "binary_big_endian")
            fail("unknown format '" + first + "' (ascii, binary_little_endian or binary_big_endian)");
        if (second != "1.0") fail("unsupported version '" + second + "' (1.0)");
    } else if (keyword == "property") {
        if (!after_an_element) fail("a property before any element");
        const bool list = first == "list";
        if (list ? !is_ply_scalar_type(second) || !is_ply_scalar_type(third) : !is_ply_scalar_type(first))
            fail("unknown property type in '" + keyword + " " + first + " " + second + (list ? " " + third : "") + "'");
    }
}

void check_ply_body(const std::filesystem::path& path, std::uintmax_t size) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    bool ascii = false;
    unsigned long long elements = 0;
    // Where the vertices' x, y and z are in an ascii body: the lines of the elements before "vertex"
    // come first, then one line per vertex with its properties in header order.
    unsigned long long lines_before_vertices = 0, vertex_count = 0;
    bool in_vertex = false, seen_vertex = false, vertex_has_list = false, seen_element = false;
    std::array<int, 3> xyz = {-1, -1, -1};
    int vertex_properties = 0;
    size_t header_lines = 0;
    for (int lines = 0;; ++lines) {
        // OpenMesh loops forever on a header without end_header, so that is caught here.
        if (!std::getline(in, line) || lines > 10000)
            throw FileError(path.string(), "truncated or malformed PLY header (no end_header)");
        ++header_lines;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream words(line);
        std::string keyword, first, second, third;
        words >> keyword >> first >> second >> third;
        if (keyword == "end_header") break;
        check_ply_header_line(path, lines + 1, keyword, first, second, third, seen_element);
        if (keyword == "format") ascii = first == "ascii";
        if (keyword == "element") {
            seen_element = true;
            const auto count = parse_count(path, second);
            check_count_fits(path, first + " elements", count, size);
            elements += count;
            in_vertex = first == "vertex" && !seen_vertex;
            if (in_vertex) {
                seen_vertex = true;
                vertex_count = count;
            } else if (!seen_vertex) {
                lines_before_vertices += count;
            }
        }
        if (keyword == "property" && in_vertex) {
            vertex_has_list = vertex_has_list || first == "list";
            const std::string& property = first == "list" ? third : second;
            for (int axis = 0; axis < 3; ++axis)
                if (property == std::string(1, char('x' + axis))) {
                    xyz[axis] = vertex_properties;
                    if (first != "float" && first != "double" && first != "float32" && first != "float64")
                        fail_ply_header(path, lines + 1, "vertex coordinate " + property + " is " + first +
                                                             "; Waxwork reads float or double coordinates");
                }
            ++vertex_properties;
        }
    }
    if (!ascii) return;
    const bool check_vertices = seen_vertex && !vertex_has_list && xyz[0] >= 0 && xyz[1] >= 0 && xyz[2] >= 0;
    unsigned long long body_lines = 0;
    size_t line_number = header_lines;
    while (std::getline(in, line)) {
        ++line_number;
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        if (check_vertices && body_lines >= lines_before_vertices && body_lines < lines_before_vertices + vertex_count) {
            std::string_view rest = line;
            std::array<std::string_view, 3> tokens;
            for (int k = 0; k < vertex_properties; ++k) {
                size_t end = 0;
                const std::string_view token = first_token(rest, end);
                rest = rest.substr(end);
                for (int axis = 0; axis < 3; ++axis)
                    if (xyz[axis] == k) tokens[axis] = token;
            }
            for (const std::string_view token : tokens) check_coordinate(path, line_number, token);
        }
        ++body_lines;
    }
    if (body_lines < elements)
        throw FileError(path.string(), "truncated: the header declares " + std::to_string(elements) +
                                           " elements but the file holds only " + std::to_string(body_lines) +
                                           " lines of them");
}

// A binary STL is an 80-byte header, a triangle count and 50 bytes per triangle; OpenMesh takes any
// file whose size does not match for ascii, so a cut binary file would read as "no faces". Files
// starting with "solid" are ascii unless their size matches the binary layout exactly (some binary
// exporters write "solid" into the header).
void check_stl_size(const std::filesystem::path& path, std::uintmax_t size) {
    std::ifstream in(path, std::ios::binary);
    char header[80] = {};
    in.read(header, sizeof header);
    const std::string start(header, header + in.gcount());
    uint32_t count = 0;
    const bool has_count = static_cast<bool>(in.read(reinterpret_cast<char*>(&count), sizeof count));
    const auto first = start.find_first_not_of(" \t\r\n");
    const bool says_solid = first != std::string::npos && start.compare(first, 5, "solid") == 0;
    // Binary STL stores the count little-endian; so do the machines Waxwork runs on.
    const std::uintmax_t binary_size = 84 + 50 * static_cast<std::uintmax_t>(count);
    if (has_count && binary_size == size) {
        check_binary_stl_coordinates(path, read_all(path), count);
        return;
    }
    if (says_solid || size < 5) {
        if (!says_solid)
            throw FileError(path.string(), "neither an ascii STL (no 'solid') nor a binary STL (too short)");
        check_vertex_lines(path, read_all(path), "vertex");
        return;
    }
    if (!has_count)
        throw FileError(path.string(), "truncated binary STL: " + std::to_string(size) +
                                           " bytes, shorter than its 84-byte header");
    throw FileError(path.string(), "not an ascii STL (no 'solid') and, as a binary STL, truncated or corrupt: "
                                   "it declares " + std::to_string(count) + " triangles (" +
                                   std::to_string(binary_size) + " bytes) but has " + std::to_string(size) + " bytes");
}

// A file's vertices and polygons as it states them; `complaint` is the reader's first warning, if any.
struct PolygonSoup {
    std::vector<Eigen::Vector3d> points;
    std::vector<std::vector<int32_t>> faces;  // -1: an index naming no vertex
    std::string complaint;
};

// OBJ, PLY and STL through OpenMesh, recording the soup as the file states it (SoupImporter).
PolygonSoup read_with_openmesh(const std::filesystem::path& path, const std::string& ext) {
    const std::string name = path.string();
    ReaderMesh mesh;
    SoupImporter importer(mesh);
    bool ok = false;
    std::string complaint;
    {
        std::lock_guard lock(reader_mutex());
        OpenMeshOutputCapture capture;
        OpenMesh::IO::Options options;  // geometry only: no normals, colours or texture coordinates
        try {
            ok = OpenMesh::IO::IOManager().read(name, importer, options);
        } catch (const std::exception& e) {
            complaint = e.what();
            ok = false;
        }
        if (complaint.empty()) complaint = capture.first_error();
    }
    if (!ok)
        throw FileError(name, "not a readable " + format_name(ext) + " file" +
                                  (complaint.empty() ? "" : " (" + complaint + ")"));
    return {importer.points(), importer.faces(), complaint};
}

// OFF through CGAL's reader: OpenMesh's takes neither the counts on the "OFF" line nor comments and
// blank lines between records (all legal OFF, written by Geomview and CGAL) and misreads them as
// missing vertices or no faces. check_off_body has already named any bad record of the plain layout.
PolygonSoup read_off(const std::filesystem::path& path) {
    using Point = CGAL::Simple_cartesian<double>::Point_3;
    std::vector<Point> cgal_points;
    std::vector<std::vector<std::size_t>> polygons;
    std::ifstream in(path, std::ios::binary);
    if (!CGAL::IO::read_OFF(in, cgal_points, polygons))
        throw FileError(path.string(), "not a readable OFF file");
    PolygonSoup soup;
    soup.points.reserve(cgal_points.size());
    for (const Point& p : cgal_points) soup.points.emplace_back(p.x(), p.y(), p.z());
    soup.faces.reserve(polygons.size());
    for (const auto& polygon : polygons) {
        std::vector<int32_t>& face = soup.faces.emplace_back();
        for (std::size_t i : polygon) face.push_back(i < soup.points.size() ? static_cast<int32_t>(i) : -1);
    }
    return soup;
}

// For each point and triangle of `repaired`, its index in `file`: a point at exactly the position of
// a file vertex (the smallest index there), a triangle on three such points that a file face joins
// too; -1 for what a repair made.
SurfaceIndexMap file_indices(const TriangleSurface& file, const TriangleSurface& repaired) {
    using Position = std::array<double, 3>;
    std::map<Position, int32_t> by_position;
    for (size_t i = 0; i < file.points.size(); ++i)
        by_position.emplace(Position{file.points[i].x(), file.points[i].y(), file.points[i].z()},
                            static_cast<int32_t>(i));
    const auto file_point = [&](const Eigen::Vector3d& p) {
        const auto it = by_position.find(Position{p.x(), p.y(), p.z()});
        return it == by_position.end() ? int32_t{-1} : it->second;
    };
    const auto key = [](std::array<int32_t, 3> t) {
        std::sort(t.begin(), t.end());
        return t;
    };
    std::map<std::array<int32_t, 3>, int32_t> by_corners;
    for (size_t t = 0; t < file.triangles.size(); ++t) {
        std::array<int32_t, 3> corners{};
        bool valid = true;
        for (int k = 0; k < 3; ++k) {
            const int32_t v = file.triangles[t][k];
            valid = valid && v >= 0 && static_cast<size_t>(v) < file.points.size();
            if (valid) corners[k] = file_point(file.points[v]);
        }
        if (valid) by_corners.emplace(key(corners), static_cast<int32_t>(t));
    }
    SurfaceIndexMap map;
    map.points.reserve(repaired.points.size());
    for (const auto& p : repaired.points) map.points.push_back(file_point(p));
    map.triangles.reserve(repaired.triangles.size());
    for (const auto& t : repaired.triangles) {
        std::array<int32_t, 3> corners{};
        bool known = true;
        for (int k = 0; k < 3; ++k) {
            known = known && t[k] >= 0 && static_cast<size_t>(t[k]) < map.points.size() && map.points[t[k]] >= 0;
            if (known) corners[k] = map.points[t[k]];
        }
        const auto it = known ? by_corners.find(key(corners)) : by_corners.end();
        map.triangles.push_back(it == by_corners.end() ? -1 : it->second);
    }
    return map;
}

}  // namespace

TriangleSurface read_surface_file(const std::filesystem::path& path) {
    const std::string name = path.string();
    const std::string ext = lower_extension(path);
    if (ext != ".obj" && ext != ".off" && ext != ".ply" && ext != ".stl")
        throw FileError(name, "unknown surface format '" + ext + "' (expected .obj, .off, .ply or .stl)");
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (!std::filesystem::exists(status)) throw FileError(name, "no such file");
    if (!std::filesystem::is_regular_file(status)) throw FileError(name, "not a regular file");
    const auto size = std::filesystem::file_size(path, error);
    if (error) throw FileError(name, "cannot read: " + error.message());
    if (size == 0) throw FileError(name, "empty file");
    if (!std::ifstream(path, std::ios::binary)) throw FileError(name, "cannot open for reading");
    if (ext == ".off") check_off_body(path, size);
    if (ext == ".ply") check_ply_body(path, size);
    if (ext == ".stl") check_stl_size(path, size);
    if (ext == ".obj") check_vertex_lines(path, read_all(path), "v");

    const PolygonSoup soup = ext == ".off" ? read_off(path) : read_with_openmesh(path, ext);
    const std::string& complaint = soup.complaint;
    const auto& faces = soup.faces;
    TriangleSurface surface;
    surface.points = soup.points;
    // The formats not checked above (PLY, binary or ascii) can still carry NaN or infinity.
    for (size_t v = 0; v < surface.points.size(); ++v) {
        if (!surface.points[v].allFinite())
            throw FileError(name, "vertex " + std::to_string(v) + " has a non-finite coordinate");
        if (surface.points[v].cwiseAbs().maxCoeff() > kMaxCoordinate)
            throw FileError(name, "vertex " + std::to_string(v) + " has a coordinate beyond " +
                                      kMaxCoordinateText + " (the renderer's float arithmetic would overflow)");
    }
    for (size_t f = 0; f < faces.size(); ++f) {
        const auto& face = faces[f];
        if (face.size() < 3)
            throw FileError(name, "face " + std::to_string(f) + " has fewer than 3 vertices");
        if (std::any_of(face.begin(), face.end(), [](int32_t i) { return i < 0; }))
            throw FileError(name, "face " + std::to_string(f) + " refers to a vertex that does not exist");
        // Polygons become fans; every format here stores planar convex polygons in practice.
        for (size_t k = 1; k + 1 < face.size(); ++k) surface.triangles.push_back({face[0], face[k], face[k + 1]});
    }
    if (surface.triangles.empty())
        throw FileError(name, "no faces" + (complaint.empty() ? std::string() : " (" + complaint + ")"));
    return surface;
}

namespace {

// Every defect describe() names can be wrapped away except those that leave no geometry to wrap: no
// triangles, or vertices that are missing or not finite (the wrap would have to drop their triangles).
bool wrapping_would_fix(const SurfaceDefects& defects) {
    return defects.triangle_count > 0 && defects.non_finite_points == 0 && defects.invalid_indices == 0;
}

// The wrap replaces the file's triangles; it is validated as any surface is, so a wrap the meshers
// could not take is refused here rather than by a mesher.
LoadedSurface wrapped_surface(TriangleSurface file, const std::string& name, const SurfaceRepairOptions& options,
                              Progress* progress) {
    WrapResult wrapped = naming_context(name, [&] { return wrap_surface(file, *options.wrap, progress); });
    LoadedSurface loaded;
    loaded.surface = std::move(wrapped.surface);
    loaded.wrap = wrapped.report;
    loaded.repairs.push_back(wrapped.report.describe());
    const size_t triangles = loaded.surface.triangles.size();
    if (options.max_triangles > 0 && triangles > options.max_triangles)
        throw InvalidMeshError(name + ": the wrap has " + std::to_string(triangles) +
                               " triangles, more than the meshers take (" + std::to_string(options.max_triangles) +
                               "); a larger --wrap-alpha gives fewer");
    report_stage(progress, "checking the wrapped surface");
    for (auto& line : repair_safe_defects(loaded.surface)) loaded.repairs.push_back(std::move(line));
    const std::vector<std::string> problems = find_surface_defects(loaded.surface).describe();
    if (!problems.empty()) {
        std::string message = name + ": the wrapped surface is still defective: ";
        for (size_t k = 0; k < problems.size(); ++k) message += (k ? "; " : "") + problems[k];
        throw InvalidMeshError(message);
    }
    return loaded;
}

}  // namespace

LoadedSurface load_closed_surface(const std::filesystem::path& path, const SurfaceRepairOptions& options,
                                  Progress* progress) {
    LoadedSurface loaded;
    report_stage(progress, "reading");
    loaded.surface = read_surface_file(path);
    if (options.max_triangles > 0) {
        if (const std::string problem = triangle_count_problem(loaded.surface.triangles.size(), options.max_triangles);
            !problem.empty())
            throw InvalidMeshError(path.string() + ": " + problem);
    }
    const std::string name = path.string();
    if (options.wrap) return wrapped_surface(std::move(loaded.surface), name, options, progress);
    const TriangleSurface file = options.fill_holes || options.autorefine ? loaded.surface : TriangleSurface{};
    report_stage(progress, "checking the surface");
    auto reject = [&](const std::vector<std::string>& defects, const SurfaceDefects& found) {
        std::string message = name + ": ";
        for (size_t k = 0; k < defects.size(); ++k) message += (k ? "; " : "") + defects[k];
        const bool wrappable = wrapping_would_fix(found);
        if (wrappable) message += "; --repair wrap rebuilds it as a closed surface";
        throw SurfaceRefusedError(message, found, wrappable);
    };

    SurfaceIndexMap origin;
    loaded.repairs = repair_safe_defects(loaded.surface, &origin);
    SurfaceDefects defects = find_surface_defects(loaded.surface);
    std::vector<std::string> problems = defects.describe(&origin);
    if (problems.empty()) return loaded;
    if (!options.fill_holes && !options.autorefine) {
        // The safe repairs were defects of the file too; name them after the blocking ones.
        for (const auto& repair : loaded.repairs) problems.push_back("also repaired: " + repair);
        reject(problems, defects);
    }

    check_cancelled(progress);
    for (auto& line : repair_hard_defects(loaded.surface, options, progress)) loaded.repairs.push_back(std::move(line));
    report_stage(progress, "checking the repaired surface");
    // After a shape-changing repair the messages still name the file's vertices and faces: those the
    // repairs kept are found again by position; those they made are marked as new.
    const SurfaceIndexMap in_file = file_indices(file, loaded.surface);
    defects = find_surface_defects(loaded.surface);
    problems = defects.describe(&in_file);
    if (!problems.empty() && std::any_of(problems.begin(), problems.end(), [](const std::string& line) {
            return line.find("[new ") != std::string::npos;
        }))
        problems.push_back("[new I]: a vertex or face the repairs made, I its number in the repaired surface; "
                           "other numbers are the file's");
    if (!problems.empty()) {
        problems.push_back("repairs tried: " + [&] {
            std::string all;
            for (size_t k = 0; k < loaded.repairs.size(); ++k) all += (k ? ", " : "") + loaded.repairs[k];
            return all;
        }());
        reject(problems, defects);
    }
    return loaded;
}

}  // namespace waxwork
