#include "bench/studies/provenance.h"

#include "build_settings.h"  // generated: compiler, flags, build type, TetGen version

#include "base/error.h"
#include "solver/mesh_resolution.h"
#ifdef WAXWORK_HAVE_PETSC
#include "solver/petsc_peers.h"
#endif
#include "tetops/quality.h"

#include <CGAL/version.h>
#include <Eigen/Core>
#include <OpenMesh/Core/System/config.h>
#include <oneapi/tbb/version.h>
#include <openssl/evp.h>
#include <sys/utsname.h>
#ifdef WAXWORK_HAVE_CHOLMOD
#include <cholmod.h>
#endif

#include <array>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>
#include <thread>

namespace waxwork {

// The build's revision, written by source_revision.cmake at build time.
extern const char* const kSourceCommit;
extern const bool kSourceDirty;

namespace {

using Json = nlohmann::ordered_json;

std::array<double, 3> load_average() {
    std::array<double, 3> load{-1, -1, -1};
    if (getloadavg(load.data(), 3) != 3) load = {-1, -1, -1};
    return load;
}

// "key : value" lines of /proc/cpuinfo or /proc/meminfo.
std::string proc_value(const char* file, const std::string& key) {
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(key, 0) == 0) {
            const size_t colon = line.find(':');
            if (colon == std::string::npos) continue;
            const size_t start = line.find_first_not_of(" \t", colon + 1);
            return start == std::string::npos ? "" : line.substr(start);
        }
    return "";
}

// Distinct (physical id, core id) pairs; 0 when /proc/cpuinfo does not say.
int physical_cores() {
    std::ifstream in("/proc/cpuinfo");
    std::set<std::pair<std::string, std::string>> cores;
    std::string line, package;
    while (std::getline(in, line)) {
        const size_t colon = line.find(':');
        if (colon == std::string::npos) continue;
        const std::string value = line.substr(std::min(line.size(), colon + 2));
        if (line.rfind("physical id", 0) == 0) package = value;
        if (line.rfind("core id", 0) == 0) cores.emplace(package, value);
    }
    return static_cast<int>(cores.size());
}

std::string operating_system() {
    std::ifstream in("/etc/os-release");
    std::string line, name = "unknown";
    while (std::getline(in, line))
        if (line.rfind("PRETTY_NAME=", 0) == 0) {
            name = line.substr(12);
            if (name.size() >= 2 && name.front() == '"') name = name.substr(1, name.size() - 2);
        }
    utsname u{};
    if (uname(&u) == 0) name += std::string(", ") + u.sysname + " " + u.release + " " + u.machine;
    return name;
}

double memory_gib() {
    const std::string total = proc_value("/proc/meminfo", "MemTotal");  // "16318412 kB"
    return total.empty() ? -1 : std::strtod(total.c_str(), nullptr) / (1024.0 * 1024.0);
}

std::string shell_quoted(const std::string& arg) {
    if (!arg.empty() && arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                              "-_./=:,+@%") == std::string::npos)
        return arg;
    std::string quoted = "'";
    for (char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

Json load_json(const std::array<double, 3>& load) { return Json::array({load[0], load[1], load[2]}); }

}  // namespace

std::string utc_timestamp() {
    const std::time_t now = std::time(nullptr);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    return text;
}

std::string command_line() {
    std::ifstream in("/proc/self/cmdline", std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string line;
    size_t start = 0;
    while (start < all.size()) {
        const size_t end = all.find('\0', start);
        const std::string arg = all.substr(start, end == std::string::npos ? std::string::npos : end - start);
        line += (line.empty() ? "" : " ") + shell_quoted(arg);
        if (end == std::string::npos) break;
        start = end + 1;
    }
    return line;
}

std::string file_sha256(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw FileError(file.string(), "cannot read the file to hash it");
    const std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context(EVP_MD_CTX_new(), EVP_MD_CTX_free);
    if (!context || EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) != 1)
        throw AlgorithmError("SHA-256: OpenSSL could not start a digest");
    std::array<char, 1 << 16> buffer;
    while (in) {
        in.read(buffer.data(), buffer.size());
        if (in.gcount() > 0) EVP_DigestUpdate(context.get(), buffer.data(), static_cast<size_t>(in.gcount()));
    }
    if (in.bad()) throw FileError(file.string(), "read error while hashing");
    std::array<unsigned char, EVP_MAX_MD_SIZE> digest;
    unsigned int length = 0;
    EVP_DigestFinal_ex(context.get(), digest.data(), &length);
    std::string hex;
    char byte[3];
    for (unsigned int i = 0; i < length; ++i) {
        std::snprintf(byte, sizeof byte, "%02x", digest[i]);
        hex += byte;
    }
    return hex;
}

Json build_provenance() {
    Json libraries = {
        {"cgal", CGAL_VERSION_STR},
        {"eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." +
                      std::to_string(EIGEN_MINOR_VERSION)},
#ifdef WAXWORK_HAVE_CHOLMOD
        {"suitesparse", std::to_string(SUITESPARSE_MAIN_VERSION) + "." + std::to_string(SUITESPARSE_SUB_VERSION) + "." +
                            std::to_string(SUITESPARSE_SUBSUB_VERSION)},
        {"cholmod", std::to_string(CHOLMOD_MAIN_VERSION) + "." + std::to_string(CHOLMOD_SUB_VERSION) + "." +
                        std::to_string(CHOLMOD_SUBSUB_VERSION)},
#else
        {"cholmod", "not built (direct solves: Eigen's SimplicialLDLT)"},
#endif
        {"onetbb", TBB_runtime_version()},
        {"tetgen", WAXWORK_TETGEN_VERSION},
        {"openmesh", std::to_string(OM_GET_VER) + "." + std::to_string(OM_GET_MAJ) + "." + std::to_string(OM_GET_MIN)},
        {"openssl", OpenSSL_version(OPENSSL_VERSION)},
#ifdef WAXWORK_HAVE_PETSC
        {"petsc", petsc_version()},
#else
        {"petsc", "not built"},
#endif
    };
    return {{"commit", kSourceCommit},
            {"dirty", kSourceDirty},
            {"compiler", WAXWORK_COMPILER},
            {"flags", WAXWORK_CXX_FLAGS},
            {"build_type", WAXWORK_BUILD_TYPE},
            {"libraries", libraries}};
}

Json mesh_inputs(const std::filesystem::path& mesh_file, const TetMesh& mesh, double mm_per_unit) {
    const QualityReport quality = measure_quality(mesh);
    return {{"mesh_file", mesh_file.string()},
            {"mesh_sha256", mesh_file.empty() ? std::string() : file_sha256(mesh_file)},
            {"tets", mesh.tet_count()},
            {"vertices", mesh.vertex_count()},
            {"mean_edge_mm", quality.mean_edge_length * mm_per_unit},
            {"min_dihedral_deg", quality.min_dihedral_deg},
            {"mm_per_unit", mm_per_unit}};
}

RunProvenance::RunProvenance(const ThreadLimit& threads)
    : threads_(threads.threads()),
      libraries_(threads.libraries()),
      started_(utc_timestamp()),
      load_start_(load_average()),
      start_(sample_cpu_usage()) {}

void RunProvenance::warn(const std::string& text) {
    std::cerr << "warning: " << text << "\n";
    warnings_.push_back(text);
}

void RunProvenance::warn_if_under_resolved(const TetMesh& mesh, const std::vector<TetMaterial>& materials,
                                           double mm_per_unit) {
    const std::string warning = under_resolution_warning(fit_to_resolution_rule(mesh, materials, mm_per_unit));
    if (!warning.empty()) warn(warning);
}

std::string provenance_caption(const Json& provenance) {
    const Json& machine = provenance.at("machine");
    const Json& build = provenance.at("build");
    const int threads = machine.at("threads_used").get<int>();
    const std::string commit = build.at("commit").get<std::string>();
    return provenance.at("started").get<std::string>().substr(0, 10) + " | " +
           machine.at("cpu_model").get<std::string>() + " | " + std::to_string(threads) +
           (threads == 1 ? " thread" : " threads") + " | commit " + commit.substr(0, 10) +
           (build.at("dirty").get<bool>() ? "+changes" : "");
}

std::string RunProvenance::caption() const {
    return provenance_caption({{"started", started_},
                               {"machine", {{"cpu_model", proc_value("/proc/cpuinfo", "model name")}, {"threads_used", threads_}}},
                               {"build", {{"commit", kSourceCommit}, {"dirty", kSourceDirty}}}});
}

Json RunProvenance::to_json(const Json& inputs, const Json& definitions) {
    const CpuUsage usage = cpu_usage_between(start_, sample_cpu_usage());
    if (usage.other_load_cores > kBusyMachineCores) {
        char text[200];
        std::snprintf(text, sizeof text,
                      "the machine was busy: other processes kept %.2f cores busy on average during the run, so its "
                      "times may be slow and noisy",
                      usage.other_load_cores);
        warn(text);
    }
    const Json machine = {
        {"cpu_model", proc_value("/proc/cpuinfo", "model name")},
        {"physical_cores", physical_cores()},
        {"hardware_threads", std::thread::hardware_concurrency()},
        {"memory_gib", memory_gib()},
        {"os", operating_system()},
        {"opengl_renderer", gl_renderer_},
        {"threads_used", threads_},
        {"threads_by_library", libraries_},
        {"load_average_start", load_json(load_start_)},
        {"load_average_end", load_json(load_average())},
        {"wall_s", usage.wall_s},
        {"process_cpu_s", usage.process_cpu_s},
        {"parallelism", usage.parallelism},
        {"other_load_cores", usage.other_load_cores},
    };
    return {{"command", command_line()}, {"started", started_},   {"ended", utc_timestamp()},
            {"machine", machine},        {"build", build_provenance()}, {"inputs", inputs},
            {"definitions", definitions}, {"warnings", warnings_}};
}

}  // namespace waxwork
