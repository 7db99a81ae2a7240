// `waxwork bench [--quick] -o DIR`: the reproducible speed-against-accuracy suite. Writes
// into DIR, each part as JSON plus a chart (SVG) or a markdown table:
//   solvers_*.json/.svg   error of phi against time for every solver path (paper Fig. 7), per mesh size
//   coarse_start.json     the best level-0 start a coarse level can give the paper's multires scheme
//   accuracy.json/.md, accuracy_ball.svg, accuracy_ball_nested.svg, accuracy_spot.svg
//                         error against tet size: the analytic ball (independent meshes and a nested 1:8
//                         family), spot against a fine reference; the table lists each fitted order
//                         with its 95% interval and whether it is reliable
//   cut_modes.json, cut_modes.svg, cut_quality.svg
//                         cross-section distance and dihedral angles of remove+relax and exact cuts
//   table1.json/.md       T_b, T_m, T_s, cut and paint per shipped model beside the paper's Table 1
//   stability.json/.md    where the methods fail and what Waxwork does (bench/studies/stability_study.h)
//   methods.json/.md, methods.svg, methods_uniform.svg, methods_spot.svg
//                         the seeds' methods (fd, fvm, lbm, dipole) beside TransCut's solvers: error against
//                         setup + solve time on the ball and on spot (bench/studies/method_study.h)
//   resolution.json/.svg  image error against per-frame cost over mesh size x tolerance
//   diffusion_vs_transport.json/.md, diffusion_vs_transport_{thickness,albedo,time}.svg
//                         the live image against the Monte Carlo image (bench/studies/transport_study.h)
//   bench.json            what ran, with what settings, how long each part took, on which machine
// Every part's JSON starts with a "provenance" block (bench/studies/provenance.h): the command, machine,
// threads, build, inputs, definitions and warnings.
// --quick (under 2 minutes here) uses smaller meshes and fewer samples, and says "(quick run)" in every
// chart and table title; the full suite takes under 20. Every chart is also written as PDF beside its
// SVG, with a caption line (date, statistic, device); every markdown table names its statistic.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace waxwork {

struct BenchSuiteOptions {
    std::filesystem::path output_dir;
    bool quick = false;
    std::filesystem::path asset_dir;                    // holds meshes/spot.obj, torus.obj, skull.obj
    std::function<void(const std::string&)> progress;   // one line per part started; may be empty
    // Run only these parts (names as in bench.json: solvers_50k, solvers_500k, coarse_start, accuracy, cut_modes, environment, table1,
    // stability, methods, resolution, diffusion_vs_transport); empty: all. An unknown name is an InvalidArgumentError.
    std::vector<std::string> only;
    // Timing statistic: 0 keeps each part's own (the solver comparison's fastest of 3 short runs, Table 1's
    // median of 3); N >= 1 makes the solver comparison and Table 1 report the median of N runs (with the
    // fastest and slowest in the solver JSON).
    int repeats = 0;
    // Threads for every library (thread_limit.h; 0: every hardware thread). Unset: the solver parts run
    // every solver on one thread, the others on every hardware thread. Each part's JSON records it.
    std::optional<int> threads;
};

// Runs every part; a part that throws is recorded in bench.json with its error and the suite goes
// on, then the first such error is rethrown at the end (so the command fails loudly but still leaves
// everything that worked). Throws FileError when DIR cannot be created or written.
void run_bench_suite(const BenchSuiteOptions& options);

}  // namespace waxwork
