// The waxwork executable: everything lives in the editor library so that tests can drive it too.
#include "app/cli.h"
#include "base/memory_reuse.h"

int main(int argc, char** argv) {
    waxwork::keep_freed_memory_for_reuse();  // an edit's large arrays reuse the previous edit's pages
    return waxwork::run_cli(argc, argv);
}
