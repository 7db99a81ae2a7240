// Fuzzing the volume readers: mutations of valid files in every format must be read into a valid
// mesh or refused with a FileError naming the file; never a crash, another exception type, or a
// mesh that breaks an invariant (which could not be rendered or saved). Deterministic: the seed and
// the case index reproduce any failure.
#include "base/error.h"
#include "io/volume_file.h"
#include "support/cli_run.h"
#include "support/fuzz_mutations.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

constexpr uint64_t kSeed = 20261128;
constexpr int kCasesPerFormat = 300;

void write_bytes(const fs::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

// The volume as another program writes it: an ascii VTK XML grid with no Waxwork arrays.
std::string ascii_vtu(const TetMesh& mesh) {
    std::ostringstream out;
    out.precision(17);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\">\n<UnstructuredGrid>\n"
        << "<Piece NumberOfPoints=\"" << mesh.vertex_count() << "\" NumberOfCells=\"" << mesh.tet_count() << "\">\n"
        << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const auto& p : mesh.positions) out << p.x() << " " << p.y() << " " << p.z() << "\n";
    out << "</DataArray></Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& t : mesh.tets) out << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (size_t t = 0; t < mesh.tet_count(); ++t) out << 4 * (t + 1) << "\n";
    out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (size_t t = 0; t < mesh.tet_count(); ++t) out << "10\n";
    out << "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
    return out.str();
}

struct FuzzTally {
    int accepted = 0, refused = 0;
};

// Reads `path` (whose bytes, or those of `mutated` for a pair, were just mutated) and checks the
// promise; returns whether it was accepted.
bool read_checks_out(const fs::path& path, const fs::path& mutated, const std::string& label, FuzzTally& tally) {
    try {
        const TetMesh mesh = read_volume(path);
        const std::vector<std::string> violations = find_invariant_violations(mesh);
        EXPECT_TRUE(violations.empty()) << label << ": accepted a mesh with " << violations.front();
        ++tally.accepted;
        return true;
    } catch (const FileError& e) {
        // A TetGen pair's error may name either file: a moved point shows up as a flat tet of the .ele.
        const fs::path partner = fs::path(path).replace_extension(".ele");
        EXPECT_TRUE(e.path() == path.string() || e.path() == mutated.string() ||
                    (path.extension() == ".node" && e.path() == partner.string()))
            << label << ": " << e.what();
        EXPECT_FALSE(e.problem().empty()) << label;
        ++tally.refused;
    } catch (const std::exception& e) {
        ADD_FAILURE() << label << ": not a FileError: " << e.what();
    }
    return false;
}

TEST(VolumeFuzz, MutatedFilesOfEveryFormatAreReadValidOrRefusedByName) {
    const fs::path dir = testing::scratch_dir("volume_fuzz");
    TetMesh mesh = testing::make_cube_mesh(2);
    mesh.materials.assign(mesh.tet_count(), TetMaterial{{0.01, 0.02, 0.03}, {1.0, 1.5, 2.0}, 1.3});
    mesh.piece_ids.assign(mesh.tet_count(), 0);
    struct Source {
        fs::path path;   // what read_volume is given
        fs::path bytes;  // the file the mutation lands in
    };
    write_volume(mesh, dir / "valid.vtu");
    write_volume(mesh, dir / "valid.msh");
    write_volume(mesh, dir / "valid.mesh");
    write_volume(mesh, dir / "valid.node");
    write_bytes(dir / "foreign.vtu", ascii_vtu(mesh));
    const std::vector<Source> sources = {{dir / "valid.vtu", dir / "valid.vtu"},   {dir / "foreign.vtu", dir / "foreign.vtu"},
                                         {dir / "valid.msh", dir / "valid.msh"},   {dir / "valid.mesh", dir / "valid.mesh"},
                                         {dir / "valid.node", dir / "valid.node"}, {dir / "valid.node", dir / "valid.ele"}};
    testing::ByteMutator mutator(kSeed);
    for (const Source& source : sources) {
        const std::string original = testing::read_text(source.bytes);
        ASSERT_NO_THROW(read_volume(source.path)) << source.path;  // the unmutated file reads
        const fs::path case_dir = dir / ("cases_" + source.bytes.filename().string());
        fs::create_directories(case_dir);
        const fs::path path = case_dir / source.path.filename(), mutated = case_dir / source.bytes.filename();
        if (source.path != source.bytes) fs::copy_file(source.path, path, fs::copy_options::overwrite_existing);
        if (source.path.extension() == ".node" && source.bytes.extension() == ".node")
            fs::copy_file(dir / "valid.ele", case_dir / "valid.ele", fs::copy_options::overwrite_existing);
        FuzzTally tally;
        for (int i = 0; i < kCasesPerFormat; ++i) {
            write_bytes(mutated, mutator.mutate(original));
            const std::string label = "seed " + std::to_string(kSeed) + " " + source.bytes.filename().string() +
                                      " case " + std::to_string(i);
            if (read_checks_out(path, mutated, label, tally)) {
                // Whatever is read can be saved and read back unchanged.
                const fs::path again = case_dir / "again.vtu";
                write_volume(read_volume(path), again);
                EXPECT_EQ(read_volume(again).tets, read_volume(path).tets) << label;
            }
        }
        // Most mutations must be caught; some (a dropped comment, a flipped bit in a number's last digit)
        // legitimately leave a valid file.
        EXPECT_GT(tally.refused, kCasesPerFormat / 3) << source.bytes;
        std::cout << "[ fuzz     ] " << source.bytes.filename().string() << ": " << kCasesPerFormat << " cases, "
                  << tally.refused << " refused by name, " << tally.accepted << " read as valid meshes\n";
    }
}

}  // namespace
}  // namespace waxwork
