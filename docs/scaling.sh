#!/usr/bin/env bash
# The measurements of docs/scaling.md: `render` of each volume with the CPU engine and with
# `--engine petsc` on 1 and 2 processes, interleaved (volume by volume, configuration by configuration,
# repeat by repeat) so that load from other processes falls on all alike; then the tables (medians).
# Usage: bash docs/scaling.sh run OUTDIR REPEATS VOLUME...   (appends to OUTDIR/runs.jsonl)
#        bash docs/scaling.sh table OUTDIR [TETS:CONFIG ...]   (the rows of runs.jsonl to show; default all;
#        CONFIG is cpu, petsc1 or petsc2, e.g. 235028:petsc1)
set -eu
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
waxwork="${WAXWORK:-$root/build/app/waxwork}"
mode="$1" out="$2"
if [ "$mode" = run ]; then
  repeats="$3"; shift 3
  mkdir -p "$out"
  for repeat in $(seq "$repeats"); do
    for volume in "$@"; do
      for config in cpu petsc1 petsc2; do
        case "$config" in
          cpu) launcher=() engine=() ;;
          petsc*) launcher=(mpirun --allow-run-as-root --oversubscribe -n "${config#petsc}") engine=(--engine petsc) ;;
        esac
        start=$(date +%s.%N)
        line=$("${launcher[@]}" /usr/bin/time -f '%M' -o "$out/rss.txt" "$waxwork" render "$volume" -o "$out/image.png" \
               --width 400 --height 300 "${engine[@]}" 2>/dev/null)
        wall=$(echo "$(date +%s.%N) - $start" | bc)
        echo "$line" | jq -c --arg volume "$(basename "$volume")" --arg config "$config" --argjson wall "$wall" \
          --argjson repeat "$repeat" --argjson rss_kib "$(tail -1 "$out/rss.txt")" \
          '. + {volume: $volume, config: $config, wall_s: $wall, repeat: $repeat, last_process_rss_kib: $rss_kib}' >> "$out/runs.jsonl"
      done
    done
  done
  rm -f "$out/image.png" "$out/rss.txt"
  exit 0
fi
shift 2
python3 - "$out/runs.jsonl" "$@" <<'PY'
import json, statistics, sys
runs = [json.loads(line) for line in open(sys.argv[1])]
wanted = {(int(w.split(":")[0]), w.split(":")[1]) for w in sys.argv[2:]}
groups = {}
for r in runs:
    if not wanted or (r["tets"], r["config"]) in wanted:
        groups.setdefault((r["tets"], r["config"]), []).append(r)
def med(values):
    return statistics.median(values)
print("| tets | engine | processes | wall (s) | lighting (ms) | assembly (ms) | AMG setup (ms) | CG (ms) | CG iterations (r, g, b) | edge cut | peak memory per process (MiB) |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for (tets, config), rs in sorted(groups.items()):
    wall = med([r["wall_s"] for r in rs])
    lighting = med([r["lighting_ms"] for r in rs])
    iterations = ", ".join(str(i) for i in rs[0]["iterations"])
    if config == "cpu":
        row = [f"{tets:,}", "cpu (Jacobi CG, TBB on both cores)", "1", f"{wall:.2f}", f"{lighting:.0f}", f"{med([r['assembly_ms'] for r in rs]):.0f}",
               "-", f"{med([r['solve_ms'] for r in rs]):.0f}", iterations, "-", f"{med([r['last_process_rss_kib'] for r in rs]) / 1024:.0f}"]
    else:
        p = [r["petsc"] for r in rs]
        processes = p[0]["processes"]
        cut = f"{p[0]['edge_cut']:,} of {p[0]['edges']:,} ({100 * p[0]['edge_cut'] / p[0]['edges']:.1f}%)"
        rss = " / ".join(f"{med([q['peak_rss_mib_per_process'][k] for q in p]):.0f}" for k in range(processes))
        row = [f"{tets:,}", "petsc (CG + BoomerAMG)", str(processes), f"{wall:.2f}", f"{lighting:.0f}",
               f"{med([q['owned_rows_assembly_ms'] + q['conversion_ms'] for q in p]):.0f}",
               f"{med([q['preconditioner_setup_ms'] for q in p]):.0f}", f"{med([q['cg_ms'] for q in p]):.0f}", iterations, cut, rss]
    print("| " + " | ".join(row) + " |")
print(f"\n- median of {len(rs)} runs per row (wall: the whole command, mpirun's start included)")
PY
