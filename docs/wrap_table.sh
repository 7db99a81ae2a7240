#!/usr/bin/env bash
# Regenerates the table of docs/meshing.md#repair-by-wrapping: every shared mesh the default meshing
# refuses, meshed with `--repair wrap` (default mesher and size unless MESHER is set), with its wall time,
# tets, components and the wrap's Hausdorff distance. Usage:
#   bash docs/wrap_table.sh [BUILD_DIR] [SHARED_MESHES] [EXTRA MESH OPTIONS...]
set -u
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
waxwork="${1:-$root/build}/app/waxwork"
meshes="${2:-$root/../shared/data/meshes}"
shift 2 2>/dev/null
out="$(mktemp -d)"
echo "| mesh | refused without the wrap for | wrap triangles | Hausdorff distance (% of diagonal) | wall time | tets | components |"
echo "|---|---|---|---|---|---|---|"
for path in "$meshes"/*.obj "$meshes"/*.off "$meshes"/*.ply "$meshes"/*.stl; do
  [ -f "$path" ] || continue
  name="$(basename "$path")"
  # Refused meshes fail in the checks, within seconds; a mesh that reaches the mesher is accepted.
  timeout 30 "$waxwork" mesh "$path" -o "$out/plain.vtu" > /dev/null 2> "$out/plain.err" &
  pid=$!
  refused=""
  while kill -0 $pid 2> /dev/null; do
    if tr '\r' '\n' < "$out/plain.err" | grep -q 'meshing'; then kill $pid; break; fi
    sleep 0.5
  done
  wait $pid 2> /dev/null
  plain_status=$?
  # Accepted: meshed at once (too fast to show a stage), or stopped once it reached the mesher.
  if [ $plain_status -ne 0 ] && ! tr '\r' '\n' < "$out/plain.err" | grep -q 'meshing'; then
    # The blocking defects, without their examples, the safe repairs and the way out.
    refused="$(tr '\r' '\n' < "$out/plain.err" | grep -v '^ *$' | tail -1 | python3 -c '
import re, sys
line = sys.stdin.read().split(": ", 2)[-1].strip()
line = re.sub(r" \([^()]*\)", "", line)
print(", ".join(p for p in line.split("; ") if not p.startswith(("also repaired", "--repair wrap"))))')"
  fi
  [ -n "$refused" ] || continue
  start=$(date +%s.%N)
  timeout 300 "$waxwork" mesh "$path" --repair wrap "$@" -o "$out/wrap.vtu" > "$out/wrap.json" 2> "$out/wrap.err"
  status=$?
  seconds=$(echo "$(date +%s.%N) - $start" | bc)
  if [ $status -ne 0 ]; then
    echo "| $name | $refused | failed (exit $status): $(tr '\r' '\n' < "$out/wrap.err" | grep -v '^ *$' | tail -1) | | $(printf %.1f "$seconds") s | | |"
    continue
  fi
  "$waxwork" info "$out/wrap.vtu" > "$out/info.json"
  python3 - "$name" "$refused" "$seconds" "$out/wrap.json" "$out/info.json" <<'PY'
import json, sys
name, refused, seconds, wrap_path, info_path = sys.argv[1:]
summary, info = json.load(open(wrap_path)), json.load(open(info_path))
w = summary["wrap"]
print(f"| {name} | {refused} | {w['triangles']} | {w['hausdorff_percent_of_diagonal']:.3f} | {float(seconds):.1f} s | "
      f"{info['tets']} | {info['components']} |")
PY
done
rm -rf "$out"
