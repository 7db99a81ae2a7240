#!/usr/bin/env bash
# Checks the layering of the source tree (docs/architecture.md):
#   1. a part includes only itself and the parts below it:
#        base < tetops < io < gl < solver < multires < render < scene < editor < bench/studies < app
#      (gl sits beside tetops and io: it may include only base); bench/studies never includes editor/;
#      the benchmark programs (bench/*.cpp) include neither editor/ nor app/; tests/X include what X
#      may include, tests/support/, and io/ (the reader of the shared test meshes);
#   2. GLFW and Dear ImGui appear only in editor/;
#   3. CLI11 appears only in app/;
#   4. stdout and exit codes (std::cout <<, printf, puts, exit, EXIT_*) appear only in app/ and in
#      the test and benchmark programs.
# Usage: check_layout.sh [SOURCE_DIR]. Prints each violation as FILE:LINE: WHY and exits 1 if any.
# One awk pass over every file: a shell loop per file took over a minute on a loaded two-core machine.
set -euo pipefail
root="${1:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
cd "$root"

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.h' '*.cpp')
else
  mapfile -t files < <(find . -name '*.h' -o -name '*.cpp' | sed 's#^\./##' | sort)
fi
existing=()
for file in "${files[@]}"; do [ -f "$file" ] && existing+=("$file"); done

awk '
BEGIN {
  allowed["base"] = " base "
  allowed["tetops"] = " base tetops "
  allowed["io"] = " base tetops io "
  allowed["gl"] = " base gl "
  allowed["solver"] = " base tetops gl solver "
  allowed["multires"] = " base tetops gl solver multires "
  allowed["render"] = " base tetops io gl solver multires render "
  allowed["scene"] = " base tetops io gl solver multires render scene "
  allowed["editor"] = " base tetops io gl solver multires render scene editor "
  allowed["studies"] = " base tetops io gl solver multires render scene bench "
  allowed["app"] = " base tetops io gl solver multires render scene editor bench app "
  allowed["benchmarks"] = " base tetops io gl solver multires render scene bench "
  folders = " base tetops io gl solver multires render scene editor bench app support "
  violations = 0
}
function layer_of(path,   rest) {
  if (path ~ /^bench\/studies\//) return "studies"
  if (path ~ /^bench\//) return "benchmarks"
  if (path ~ /^tests\/support\//) return "app"
  if (path ~ /^tests\/studies\//) return "studies"
  if (path ~ /^tests\/[^\/]+\//) { rest = substr(path, 7); return substr(rest, 1, index(rest, "/") - 1) }
  if (index(path, "/")) return substr(path, 1, index(path, "/") - 1)
  return ""
}
function report(why) { print FILENAME ":" FNR ": " why; violations++ }
FNR == 1 { layer = layer_of(FILENAME); in_tests = FILENAME ~ /^tests\//; skip = !(layer in allowed) }
skip { next }
/^[[:space:]]*\/\// { next }
/^[[:space:]]*#[[:space:]]*include[[:space:]]*"/ {
  target = $0
  sub(/^[^"]*"/, "", target); sub(/".*$/, "", target)
  if (index(target, "/")) {
    folder = substr(target, 1, index(target, "/") - 1)
    if (index(folders, " " folder " ")) {
      if (folder == "support") {
        if (!in_tests) report("includes the test support folder")
      } else {
        permitted = allowed[layer] (in_tests ? " io " : "")
        if (!index(permitted, " " folder " ")) report(layer " may not include " folder "/ (" target ")")
        else if (layer == "studies" && folder == "bench" && target !~ /^bench\/studies\//)
          report("studies include only bench/studies/ of bench/ (" target ")")
      }
    }
  }
}
/#[[:space:]]*include[[:space:]]*[<"](GLFW\/|imgui|backends\/imgui)/ && layer != "editor" { report("GLFW or ImGui outside editor/") }
/#[[:space:]]*include[[:space:]]*[<"]CLI\// && layer != "app" { report("CLI11 outside app/") }
layer != "app" && !in_tests && layer != "benchmarks" &&
  /std::cout[[:space:]]*<<|(^|[^_[:alnum:]:.>])(std::)?(exit|quick_exit|_Exit)[[:space:]]*\(|EXIT_(SUCCESS|FAILURE)|(^|[^_[:alnum:]])(std::)?(printf|puts)[[:space:]]*\(/ {
  report("stdout or an exit code outside app/")
}
END {
  if (violations) { print "layout: " violations " violation(s) of the rules in docs/architecture.md"; exit 1 }
  print "layout: " ARGC - 1 " files follow the layering rules"
}
' "${existing[@]}"
