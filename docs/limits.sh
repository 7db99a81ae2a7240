#!/usr/bin/env bash
# Regenerates the measurements of docs/meshing.md#limits: each case under `timeout 120`, with its time,
# peak memory and the stages it went through. Usage: bash docs/limits.sh [BUILD_DIR] [SHARED_MESHES]
set -u
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
waxwork="${1:-$root/build}/app/waxwork"
meshes="${2:-$root/../shared/data/meshes}"
out="$(mktemp -d)"
python3 - "$out/sphere2m.obj" <<'PY'
import math, sys
n = 1000  # a UV sphere of n x n quads: 1,998,000 triangles
verts = [(0, 0, 1)] + [(math.sin(math.pi*i/n)*math.cos(2*math.pi*j/n), math.sin(math.pi*i/n)*math.sin(2*math.pi*j/n),
                        math.cos(math.pi*i/n)) for i in range(1, n) for j in range(n)] + [(0, 0, -1)]
v = lambda i, j: 1 + (i-1)*n + j % n
tris = [(0, v(1, j), v(1, j+1)) for j in range(n)]
for i in range(1, n-1):
    for j in range(n):
        tris += [(v(i, j), v(i+1, j), v(i+1, j+1)), (v(i, j), v(i+1, j+1), v(i, j+1))]
tris += [(len(verts)-1, v(n-1, j+1), v(n-1, j)) for j in range(n)]
with open(sys.argv[1], 'w') as f:
    f.write(''.join('v %.9f %.9f %.9f\n' % p for p in verts))
    f.write(''.join('f %d %d %d\n' % (a+1, b+1, c+1) for a, b, c in tris))
PY
sed '1s/.*/v 1000.000000 1.000000 -1.000000/' "$meshes/cube.obj" > "$out/needle.obj"
run() {
  echo "== waxwork mesh $*"
  /usr/bin/time -f "%e s, %M KB" timeout 120 "$waxwork" mesh "$@" -o "$out/x.vtu" 2> "$out/err" > "$out/out"
  echo "exit $?"
  tr '\r' '\n' < "$out/err" | grep -v '^ *$' | awk -F'\\.\\.\\. ' '{k=$1; last[k]=$0; if (!(k in seen)) {seen[k]=1; order[++n]=k}}
    END {for (i = 1; i <= n; i++) print last[order[i]]}'
  cut -c1-200 "$out/out"
}
run "$meshes/bad_stanford-bunny.obj" --fill-holes
run "$meshes/horse.ply" --autorefine
run "$meshes/horse.ply" --autorefine --mesher cgal
run "$out/sphere2m.obj"
run "$out/sphere2m.obj" --mesher cgal
run "$out/needle.obj"
run "$out/needle.obj" --mesher cgal
run "$root/assets/meshes/spot.obj" --max-tets 2000000
run "$root/assets/meshes/spot.obj" --max-tets 50000000
rm -rf "$out"
