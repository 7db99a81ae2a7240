// The command line: `waxwork SUBCOMMAND ...`. Exit status 0 on success; on failure a single line
// "waxwork: MESSAGE" on stderr and a non-zero status (1 for errors in the work, 2 for usage errors).
#pragma once

namespace waxwork {

int run_cli(int argc, char** argv);

}  // namespace waxwork
