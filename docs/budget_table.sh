#!/usr/bin/env bash
# Regenerates the table of docs/meshing.md#tet-budgets: `waxwork mesh` with the default mesher (auto) at
# --max-tets 20000 on spot, armadillo, the skull and the wrapped horse, spot at 1000, and the skull at its
# default size, one markdown row each (tets, wall time, the meshing's own time, min dihedral, tets under 5
# degrees, the remeshed surface). Usage: bash docs/budget_table.sh [BUILD_DIR] [SHARED_MESHES]
set -u
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
waxwork="${1:-$root/build}/app/waxwork"
meshes="${2:-$root/../shared/data/meshes}"
out="$(mktemp -d)"
echo "| case | tets | wall time (load) | meshing time | min dihedral | under 5 deg | surface remeshed (triangles in -> out, edge) |"
echo "|---|---|---|---|---|---|---|"
run() {
  name=$1; shift
  load=$(cut -d' ' -f1 /proc/loadavg)
  start=$(date +%s.%N)
  timeout 400 "$waxwork" mesh "$@" -o "$out/x.vtu" 2> "$out/err" > "$out/out"
  wall=$(echo "$(date +%s.%N) - $start" | bc)
  python3 - "$name" "$wall" "$load" "$out/out" <<'PY'
import json, sys
name, wall, load, path = sys.argv[1:]
try:
    j = json.load(open(path))
except Exception:
    print(f"| {name} | failed | {float(wall):.1f} s ({load}) | | | | |"); sys.exit()
r = j.get("surface_remeshed")
rem = f"{r['triangles_in']:,} -> {r['triangles_out']:,}, {r['edge']:.4g}" if r else "no"
print(f"| {name} | {j['tets']:,} | {float(wall):.1f} s ({load}) | {j['milliseconds']/1000:.1f} s | "
      f"{j['min_dihedral_deg']:.2f} | {j['tets_below_5_deg']} | {rem} |")
PY
}
run "spot --max-tets 1000" "$meshes/spot.obj" --max-tets 1000
run "spot --max-tets 20000" "$meshes/spot.obj" --max-tets 20000
run "armadillo --max-tets 20000" "$meshes/armadillo.obj" --max-tets 20000
run "skull --max-tets 20000" "$meshes/skull.obj" --max-tets 20000
run "horse --repair wrap --max-tets 20000" "$meshes/horse.ply" --repair wrap --max-tets 20000
run "skull, default size" "$meshes/skull.obj"
run "spot, default size" "$meshes/spot.obj"
rm -rf "$out"
