#include "io/surface_writer.h"

#include "base/error.h"
#include "io/atomic_file.h"
#include "io/file_extension.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <ostream>
#include <string>

namespace waxwork {

namespace {

// Little-endian bytes of a number, whatever the host's order (PLY and STL name it).
template <typename T>
void put_le(std::ostream& out, T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
    out.write(bytes, sizeof(T));
}

// The shortest decimal that reads back as the same double.
void put_exact(std::ostream& out, double value) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, value).ptr;
    out.write(text, end - text);
}

void write_ply(std::ostream& out, const BoundaryShells& shells, std::span<const std::array<uint8_t, 3>> colours) {
    out << "ply\nformat binary_little_endian 1.0\ncomment written by Waxwork\n";
    out << "element vertex " << shells.positions.size() << "\n";
    out << "property double x\nproperty double y\nproperty double z\n";
    if (!colours.empty()) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    out << "element face " << shells.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (size_t v = 0; v < shells.positions.size(); ++v) {
        for (int k = 0; k < 3; ++k) put_le(out, shells.positions[v][k]);
        if (!colours.empty())
            for (uint8_t c : colours[v]) put_le(out, c);
    }
    for (const auto& triangle : shells.triangles) {
        put_le(out, uint8_t{3});
        for (int32_t v : triangle) put_le(out, v);
    }
}

void write_obj(std::ostream& out, const BoundaryShells& shells, std::span<const std::array<uint8_t, 3>> colours) {
    out << "# written by Waxwork: " << shells.positions.size() << " vertices, " << shells.triangles.size()
        << " triangles\n";
    const bool groups = shells.grouping == ShellGrouping::Separate;
    char colour[16];
    for (size_t s = 0; s < shells.shell_count(); ++s) {
        if (groups) out << "o piece_" << s + 1 << "\n";
        for (int32_t v = shells.vertex_offsets[s]; v < shells.vertex_offsets[s + 1]; ++v) {
            out << "v ";
            put_exact(out, shells.positions[v].x());
            out << ' ';
            put_exact(out, shells.positions[v].y());
            out << ' ';
            put_exact(out, shells.positions[v].z());
            // Six decimals of c / 255: a reader that scales by 255 and rounds gets c back.
            if (!colours.empty())
                for (uint8_t c : colours[v]) {
                    const auto end = std::to_chars(colour, colour + sizeof colour, c / 255.0, std::chars_format::fixed, 6).ptr;
                    out << ' ';
                    out.write(colour, end - colour);
                }
            out << '\n';
        }
        for (int32_t t = shells.shell_offsets[s]; t < shells.shell_offsets[s + 1]; ++t) {
            const auto& triangle = shells.triangles[t];
            out << "f " << triangle[0] + 1 << ' ' << triangle[1] + 1 << ' ' << triangle[2] + 1 << '\n';
        }
    }
}

void write_stl(std::ostream& out, const BoundaryShells& shells) {
    // The 80-byte header must not start with "solid" (readers would take the file for ASCII STL).
    std::string header = "binary STL written by Waxwork";
    header.resize(80, ' ');
    out.write(header.data(), 80);
    put_le(out, static_cast<uint32_t>(shells.triangles.size()));
    for (const auto& triangle : shells.triangles) {
        const Eigen::Vector3d& a = shells.positions[triangle[0]];
        const Eigen::Vector3d& b = shells.positions[triangle[1]];
        const Eigen::Vector3d& c = shells.positions[triangle[2]];
        const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();  // zero when degenerate
        for (int k = 0; k < 3; ++k) put_le(out, static_cast<float>(normal[k]));
        for (const Eigen::Vector3d* p : {&a, &b, &c})
            for (int k = 0; k < 3; ++k) put_le(out, static_cast<float>((*p)[k]));
        put_le(out, uint16_t{0});
    }
}

}  // namespace

SurfaceFormat surface_format(const std::filesystem::path& path) {
    const std::string extension = lower_extension(path);
    if (extension == ".ply") return SurfaceFormat::Ply;
    if (extension == ".obj") return SurfaceFormat::Obj;
    if (extension == ".stl") return SurfaceFormat::Stl;
    throw InvalidArgumentError(path.string() + ": unknown surface format '" + path.extension().string() +
                               "' (write .ply, .obj or .stl)");
}

bool stores_vertex_colours(SurfaceFormat format) { return format != SurfaceFormat::Stl; }

void write_surface(const std::filesystem::path& path, const BoundaryShells& shells,
                   std::span<const std::array<uint8_t, 3>> colours) {
    const SurfaceFormat format = surface_format(path);
    if (!colours.empty() && !stores_vertex_colours(format))
        throw InvalidArgumentError(path.string() + ": STL has no standard vertex colours; write .ply or .obj");
    if (!colours.empty() && colours.size() != shells.positions.size())
        throw InvalidArgumentError(path.string() + ": " + std::to_string(colours.size()) + " colours for " +
                                   std::to_string(shells.positions.size()) + " vertices");
    write_file_atomically(path, [&](std::ostream& out) {
        switch (format) {
            case SurfaceFormat::Ply: write_ply(out, shells, colours); break;
            case SurfaceFormat::Obj: write_obj(out, shells, colours); break;
            case SurfaceFormat::Stl: write_stl(out, shells); break;
        }
    });
}

}  // namespace waxwork
