// The waxwork executable: everything lives in the editor library so that tests can drive it too.
#include "editor/cli.h"

int main(int argc, char** argv) { return waxwork::run_cli(argc, argv); }
