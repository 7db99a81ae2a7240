#!/usr/bin/env bash
# Prints the table of docs/benchmarks.md#solvers-against-each-other from the solver comparisons' JSON
# (default: assets/docs/bench/solvers_spot_50k.json and solvers_spot_500k.json, written by
# `waxwork bench -o assets/docs/bench --only solvers_50k,solvers_500k --repeats N`): per solver, the time
# to 1% error as the statistic the JSON names (median) with its fastest and slowest run, the per-mesh
# setup, the CPU time per wall second the solver used ("cores") and, in brackets, the cores other
# processes kept busy meanwhile.
# Usage: bash docs/solvers_table.sh [JSON ...]
set -eu
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ $# -eq 0 ]; then set -- "$root/assets/docs/bench/solvers_spot_50k.json" "$root/assets/docs/bench/solvers_spot_500k.json"; fi
python3 - "$@" <<'PY'
import json, sys
runs = [json.load(open(path)) for path in sys.argv[1:]]
labels = {
    "jacobi_cg": "Jacobi CG, float (three channels interleaved)",
    "jacobi_cg_double": "Jacobi CG, double",
    "multires": "multires (paper: coarse to fine, BiCGSTAB + CG)",
    "multigrid_cg": "multigrid-preconditioned CG, per channel",
    "cascadic_cg": "cascadic CG (the paper's pass on Galerkin coarse systems)",
    "multigrid_cg_rgb": "multigrid-preconditioned CG, three channels in one pass (the editor's frame solver)",
    "eigen_ic_cg": "Eigen CG + IncompleteCholesky",
    "petsc_cg_gamg": "PETSc CG + GAMG (smoothed aggregation)",
    "petsc_cg_boomeramg": "PETSc CG + hypre BoomerAMG (HMIS, ext+i)",
    "gpu_cg": "GPU CG on llvmpipe (a CPU: not GPU speed)",
    "gpu_multires": "GPU multires on llvmpipe",
    "gpu_multigrid_cg": "GPU multigrid CG on llvmpipe",
    "direct": "CHOLMOD direct (the solves; factorisation in setup)",
}
def ms(v):
    return f"{v:.3g}" if v < 1000 else f"{v / 1000:.3g} s"
header = "| solver |"
rule = "|---|"
for r in runs:
    p = r["provenance"]["machine"]
    header += f" {r['tets']:,} tets: to 1% (ms) | setup (ms) | cores (others) |"
    rule += "---|---|---|"
print(header)
print(rule)
names = [n for n in labels if any(n in r["solvers"] for r in runs)]
for name in names:
    line = f"| {labels[name]} |"
    for r in runs:
        s = r["solvers"].get(name)
        if s is None or s["time_to_1pct_ms"] is None:
            line += " - | - | - |"
            continue
        line += (f" {ms(s['time_to_1pct_ms'])} ({ms(s['time_to_1pct_ms_min'])}-{ms(s['time_to_1pct_ms_max'])}) |"
                 f" {ms(s['setup_ms'])} | {s['parallelism']:.2f} ({s['other_load_cores']:.2f}) |")
    print(line)
print()
for r in runs:
    p = r["provenance"]
    m = p["machine"]
    print(f"- {r['tets']:,} tets: {r['statistic']}; {m['threads_used']} thread(s); {p['started'][:10]}, "
          f"{m['cpu_model']}, commit {p['build']['commit'][:10]}{' (with changes)' if p['build']['dirty'] else ''}; "
          f"other processes kept {m['other_load_cores']:.2f} cores busy"
          + ("; warnings: " + "; ".join(p["warnings"]) if p["warnings"] else ""))
PY
