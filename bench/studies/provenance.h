// What a reader needs to trust a measurement and to run it again, written as the "provenance" object of
// every JSON the benchmarks write:
//   command      the command line that wrote the file (run it again to regenerate the file and its chart)
//   started, ended    UTC, ISO 8601
//   machine      CPU model, physical cores, hardware threads, memory, OS, OpenGL renderer, the threads
//                the run allowed each library (thread_limit.h), the load average at the start and the
//                end, and what cpu_usage.h measured over the run: the process's CPU seconds per wall
//                second ("parallelism") and the cores other processes kept busy
//   build        the commit and whether tracked files differed from it when the program was built,
//                the compiler and its flags, the build type, and the libraries' versions
//   inputs       what was measured (the caller's; mesh_inputs() for a volume)
//   definitions  the error norm, the reference and how it was obtained, the stopping rule, the units
//                of every count (the caller's)
//   warnings     an under-resolved mesh (solver/mesh_resolution.h), a busy machine
#pragma once

#include "bench/studies/cpu_usage.h"
#include "bench/studies/thread_limit.h"
#include "tetops/tet_mesh.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace waxwork {

// Other processes keeping more than this many cores busy on average make a run's timings suspect.
inline constexpr double kBusyMachineCores = 0.5;

class RunProvenance {
public:
    // Samples the start (time, load average, CPU usage). `threads`: the limit the run is under.
    explicit RunProvenance(const ThreadLimit& threads);

    // The OpenGL renderer string of the context the GPU curves ran on ("" when none ran).
    void set_gl_renderer(std::string renderer) { gl_renderer_ = std::move(renderer); }

    // Records a warning and prints it to stderr as "warning: TEXT".
    void warn(const std::string& text);

    // Warns when `mesh` under-resolves the diffusion length of `materials` (per tet) at mm_per_unit
    // (solver/mesh_resolution.h under_resolution_warning).
    void warn_if_under_resolved(const TetMesh& mesh, const std::vector<TetMaterial>& materials, double mm_per_unit);

    // provenance_caption() of the run so far (date, CPU, threads, commit), for charts drawn before the
    // block is written.
    std::string caption() const;

    // The block, sampling the end now; adds the busy-machine warning (printed too) when other processes
    // kept more than kBusyMachineCores cores busy on average since the start.
    nlohmann::ordered_json to_json(const nlohmann::ordered_json& inputs, const nlohmann::ordered_json& definitions);

private:
    int threads_;
    nlohmann::ordered_json libraries_;
    std::string started_;
    std::array<double, 3> load_start_{};
    CpuSample start_;
    std::string gl_renderer_;
    std::vector<std::string> warnings_;
};

// A volume's inputs: {"mesh_file", "mesh_sha256", "tets", "vertices", "mean_edge_mm",
// "min_dihedral_deg", "mm_per_unit"}; mesh_file "" for a generated volume (then no hash).
nlohmann::ordered_json mesh_inputs(const std::filesystem::path& mesh_file, const TetMesh& mesh, double mm_per_unit);

// The SHA-256 of a file's bytes in hex (as `sha256sum` prints it); throws FileError when unreadable.
std::string file_sha256(const std::filesystem::path& file);

// This process's command line, its arguments shell-quoted where needed.
std::string command_line();

// The build: {"commit", "dirty", "compiler", "flags", "build_type", "libraries": {...}}.
nlohmann::ordered_json build_provenance();

// One caption line for a chart from a provenance block: "DATE | CPU | N thread(s) | commit C[+changes]".
std::string provenance_caption(const nlohmann::ordered_json& provenance);

// The current UTC time, ISO 8601 ("2026-11-28T17:45:56Z").
std::string utc_timestamp();

}  // namespace waxwork
