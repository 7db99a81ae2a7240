#!/usr/bin/env bash
# Checks the layering of the source tree (docs/architecture.md):
#   1. a folder includes only itself and the folders below it:
#        base < tetops < io < gl < solver < multires < render < scene < editor < bench/studies < app
#      (gl sits beside tetops and io: it may include only base); bench/studies never includes editor/;
#      the benchmark programs (bench/*.cpp) include neither editor/ nor app/; tests/X include what X
#      may include, tests/support/, and io/ (the reader of the shared test meshes);
#   2. GLFW and Dear ImGui appear only in editor/;
#   3. CLI11 appears only in app/;
#   4. stdout and exit codes (std::cout <<, printf, puts, exit, EXIT_*) appear only in app/ and in
#      the test and benchmark programs.
# Usage: check_layout.sh SOURCE_DIR. Prints each violation as FILE:LINE: WHY and exits 1 if any.
set -uo pipefail
root="${1:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
cd "$root" || exit 2

declare -A allowed=(
  [base]="base"
  [tetops]="base tetops"
  [io]="base tetops io"
  [gl]="base gl"
  [solver]="base tetops gl solver"
  [multires]="base tetops gl solver multires"
  [render]="base tetops io gl solver multires render"
  [scene]="base tetops io gl solver multires render scene"
  [editor]="base tetops io gl solver multires render scene editor"
  [studies]="base tetops io gl solver multires render scene bench"
  [app]="base tetops io gl solver multires render scene editor bench app"
  [benchmarks]="base tetops io gl solver multires render scene bench"
)
project_folders="base tetops io gl solver multires render scene editor bench app"

violations=0
report() { echo "$1: $2"; violations=$((violations + 1)); }

# The layer of a source file, or nothing for files outside the layered tree.
layer_of() {
  case "$1" in
    bench/studies/*) echo studies ;;
    bench/*) echo benchmarks ;;
    tests/support/*) echo app ;;
    tests/studies/*) echo studies ;;
    tests/*/*) local rest="${1#tests/}"; echo "${rest%%/*}" ;;
    */*) echo "${1%%/*}" ;;
  esac
}

mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.h' '*.cpp' 2>/dev/null || find . -name '*.h' -o -name '*.cpp' | sed 's#^\./##')
for file in "${files[@]}"; do
  layer="$(layer_of "$file")"
  [ -n "$layer" ] && [ -n "${allowed[$layer]+x}" ] || continue
  in_tests=0; [[ "$file" == tests/* ]] && in_tests=1
  while IFS=: read -r line text; do
    target="$(sed -E 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"([^"]+)".*/\1/' <<<"$text")"
    folder="${target%%/*}"
    [ "$folder" = "$target" ] && continue  # a file beside it
    case " $project_folders support " in *" $folder "*) ;; *) continue ;; esac
    if [ "$folder" = support ]; then
      [ "$in_tests" = 1 ] || report "$file:$line" "includes the test support folder"
      continue
    fi
    permitted=" ${allowed[$layer]} "
    [ "$in_tests" = 1 ] && permitted+=" io "
    case "$permitted" in
      *" $folder "*) ;;
      *) report "$file:$line" "$layer may not include $folder/ ($target)" ;;
    esac
    if [ "$layer" = studies ] || [ "$layer" = benchmarks ]; then
      [[ "$target" == bench/studies/* || "$folder" != bench ]] || [ "$layer" = benchmarks ] ||
        report "$file:$line" "studies include only bench/studies/ of bench/ ($target)"
    fi
  done < <(grep -n -E '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file")

  code="$(grep -n -v -E '^[[:space:]]*//' "$file")"
  if [ "$layer" != editor ]; then
    while IFS= read -r hit; do [ -n "$hit" ] && report "$file:${hit%%:*}" "GLFW or ImGui outside editor/"; done \
      < <(grep -E '#[[:space:]]*include[[:space:]]*[<"](GLFW/|imgui|backends/imgui)' <<<"$code")
  fi
  if [ "$layer" != app ]; then
    while IFS= read -r hit; do [ -n "$hit" ] && report "$file:${hit%%:*}" "CLI11 outside app/"; done \
      < <(grep -E '#[[:space:]]*include[[:space:]]*[<"]CLI/' <<<"$code")
  fi
  if [ "$layer" != app ] && [ "$in_tests" = 0 ] && [ "$layer" != benchmarks ]; then
    while IFS= read -r hit; do [ -n "$hit" ] && report "$file:${hit%%:*}" "stdout or an exit code outside app/"; done \
      < <(grep -E 'std::cout[[:space:]]*<<|(^|[^_[:alnum:]:.>])(std::)?(exit|quick_exit|_Exit)[[:space:]]*\(|EXIT_(SUCCESS|FAILURE)|(^|[^_[:alnum:]])(std::)?(printf|puts)[[:space:]]*\(' <<<"$code")
  fi
done

if ((violations)); then
  echo "layout: $violations violation(s) of the rules in docs/architecture.md"
  exit 1
fi
echo "layout: ${#files[@]} files follow the layering rules"
