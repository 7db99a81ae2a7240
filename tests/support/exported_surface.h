// Reading back what `waxwork export` writes, exactly (double coordinates as written), and the checks
// its tests make: the volume a surface encloses and whether each shell is closed.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace waxwork::testing {

struct ReadSurface {
    std::vector<Eigen::Vector3d> positions;
    std::vector<std::array<int32_t, 3>> triangles;
    std::vector<std::array<uint8_t, 3>> colours;  // empty when the file has none
    std::vector<std::string> groups;              // OBJ `o` names
    std::vector<size_t> group_triangle_offsets;   // triangles of group g: [offsets[g], offsets[g+1])
};

inline std::string file_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

template <typename T>
T read_le(const std::string& bytes, size_t& at) {
    T value;
    std::memcpy(&value, bytes.data() + at, sizeof(T));  // the test machines are little-endian
    at += sizeof(T);
    return value;
}

// The layout write_surface gives PLY: binary little-endian, double x y z, optional uchar rgb,
// triangles as uchar-counted int lists.
inline ReadSurface read_exported_ply(const std::filesystem::path& path) {
    const std::string bytes = file_bytes(path);
    const size_t end = bytes.find("end_header\n");
    EXPECT_NE(end, std::string::npos) << path;
    std::istringstream header(bytes.substr(0, end));
    size_t vertices = 0, faces = 0;
    bool colours = false;
    for (std::string line; std::getline(header, line);) {
        std::istringstream words(line);
        std::string a, b, c;
        words >> a >> b >> c;
        if (a == "format") {
            EXPECT_EQ(b, "binary_little_endian");
        }
        if (a == "element" && b == "vertex") vertices = std::stoul(c);
        if (a == "element" && b == "face") faces = std::stoul(c);
        if (a == "property" && b == "double") {
            EXPECT_TRUE(c == "x" || c == "y" || c == "z") << line;
        }
        if (a == "property" && c == "red") colours = true;
    }
    ReadSurface s;
    size_t at = end + std::strlen("end_header\n");
    for (size_t v = 0; v < vertices; ++v) {
        Eigen::Vector3d p;
        for (int k = 0; k < 3; ++k) p[k] = read_le<double>(bytes, at);
        s.positions.push_back(p);
        if (colours) {
            std::array<uint8_t, 3> rgb;
            for (auto& c : rgb) c = read_le<uint8_t>(bytes, at);
            s.colours.push_back(rgb);
        }
    }
    for (size_t f = 0; f < faces; ++f) {
        EXPECT_EQ(read_le<uint8_t>(bytes, at), 3);
        std::array<int32_t, 3> t;
        for (auto& v : t) v = read_le<int32_t>(bytes, at);
        s.triangles.push_back(t);
    }
    EXPECT_EQ(at, bytes.size()) << path;
    return s;
}

// OBJ: `v x y z [r g b]` (colours in [0, 1], scaled back to bytes), `o NAME`, `f a b c` (1-based).
inline ReadSurface read_exported_obj(const std::filesystem::path& path) {
    std::ifstream in(path);
    ReadSurface s;
    for (std::string line; std::getline(in, line);) {
        std::istringstream words(line);
        std::string kind;
        words >> kind;
        if (kind == "v") {
            Eigen::Vector3d p;
            words >> p.x() >> p.y() >> p.z();
            s.positions.push_back(p);
            double r, g, b;
            if (words >> r >> g >> b)
                s.colours.push_back({uint8_t(std::lround(r * 255)), uint8_t(std::lround(g * 255)),
                                     uint8_t(std::lround(b * 255))});
        } else if (kind == "o") {
            std::string name;
            words >> name;
            s.groups.push_back(name);
            s.group_triangle_offsets.push_back(s.triangles.size());
        } else if (kind == "f") {
            std::array<int32_t, 3> t;
            for (auto& v : t) {
                words >> v;
                --v;
            }
            EXPECT_TRUE(words) << line;
            s.triangles.push_back(t);
        }
    }
    if (!s.groups.empty()) s.group_triangle_offsets.push_back(s.triangles.size());
    return s;
}

// Binary STL: float32 coordinates, one vertex per triangle corner (welded here by exact position).
inline ReadSurface read_exported_stl(const std::filesystem::path& path) {
    const std::string bytes = file_bytes(path);
    size_t at = 80;
    const auto count = read_le<uint32_t>(bytes, at);
    EXPECT_EQ(bytes.size(), 84 + 50 * size_t(count)) << path;
    ReadSurface s;
    std::map<std::array<float, 3>, int32_t> index;
    for (uint32_t f = 0; f < count; ++f) {
        for (int k = 0; k < 3; ++k) read_le<float>(bytes, at);  // the facet normal
        std::array<int32_t, 3> t;
        for (auto& v : t) {
            std::array<float, 3> p;
            for (auto& x : p) x = read_le<float>(bytes, at);
            auto [it, added] = index.emplace(p, int32_t(s.positions.size()));
            if (added) s.positions.emplace_back(p[0], p[1], p[2]);
            v = it->second;
        }
        read_le<uint16_t>(bytes, at);
        s.triangles.push_back(t);
    }
    return s;
}

inline ReadSurface read_exported(const std::filesystem::path& path) {
    const std::string extension = path.extension().string();
    if (extension == ".ply") return read_exported_ply(path);
    if (extension == ".obj") return read_exported_obj(path);
    return read_exported_stl(path);
}

// The signed volume the triangles [first, last) enclose (divergence theorem: the sum of the
// tetrahedra from the origin to each triangle); positive when they face outward.
inline double enclosed_volume(const ReadSurface& s, size_t first = 0, size_t last = size_t(-1)) {
    last = std::min(last, s.triangles.size());
    double volume = 0;
    for (size_t t = first; t < last; ++t) {
        const auto& [a, b, c] = s.triangles[t];
        volume += s.positions[a].dot(s.positions[b].cross(s.positions[c])) / 6;
    }
    return volume;
}

// Whether the triangles [first, last) form closed, consistently oriented shells: every directed edge
// is matched by as many of its reverse (an edge where two parts touch may carry two pairs).
inline bool closed_and_oriented(const ReadSurface& s, size_t first = 0, size_t last = size_t(-1)) {
    last = std::min(last, s.triangles.size());
    std::map<std::pair<int32_t, int32_t>, int> balance;
    for (size_t t = first; t < last; ++t)
        for (int k = 0; k < 3; ++k) {
            const int32_t a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
            balance[{std::min(a, b), std::max(a, b)}] += a < b ? 1 : -1;
        }
    for (const auto& [edge, count] : balance)
        if (count != 0) return false;
    return !balance.empty();
}

}  // namespace waxwork::testing
