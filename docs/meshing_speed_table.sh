#!/usr/bin/env bash
# Regenerates the table of docs/meshing.md#default-meshing-against-tetgen--pq: for every shared mesh, the
# default meshing (`waxwork mesh FILE`: auto, marble's graded size at the model's default scale; a broken
# mesh wrapped first, as `--repair wrap` does) against TetGen's own quality run (`tetgen -pq`) of the same
# surface, from bench/meshing_bench (DefaultAgainstTetGenPq/<mesh>).
# Usage: bash docs/meshing_speed_table.sh [BUILD_DIR]
set -eu
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bench="${1:-$root/build}/bench/meshing_bench"
json="$(mktemp)"
trap 'rm -f "$json"' EXIT
"$bench" --benchmark_filter=DefaultAgainstTetGenPq --benchmark_format=json > "$json"
python3 - "$json" <<'PY'
import json, sys
rows = json.load(open(sys.argv[1]))["benchmarks"]
print("| mesh | triangles | default: tets | time | min dihedral | under 5 deg | `-pq`: tets | time | min dihedral | under 5 deg | time / `-pq` | time per tet / `-pq`'s |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    name = r["name"].split("/")[1]
    notes = [n for n, flag in (("wrapped", r["wrapped"]), ("remeshed", r["remeshed"])) if flag]
    label = f"{name} ({', '.join(notes)})" if notes else name
    print(f"| {label} | {int(r['triangles']):,} | {int(r['tets']):,} | {r['ms'] / 1000:.2f} s | {r['min_dihedral']:.2f} | "
          f"{int(r['under_5_deg'])} | {int(r['pq_tets']):,} | {r['pq_ms'] / 1000:.2f} s | {r['pq_min_dihedral']:.2f} | "
          f"{int(r['pq_under_5_deg'])} | {r['ratio']:.2f} | {r['ratio_per_tet']:.2f} |")
PY
