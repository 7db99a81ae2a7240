#include "solver/petsc_runtime.h"

#include "base/error.h"

#include <petscsys.h>

#include <string>

namespace waxwork {
namespace {

class PetscRuntime {
public:
    PetscRuntime() {
        PetscBool initialized = PETSC_FALSE;
        if (PetscInitialized(&initialized) != 0)
            throw AlgorithmError("PETSc: cannot query whether it is initialised");
        if (initialized) return;  // the program's own PetscInitialize: its finalisation too
        if (const PetscErrorCode code = PetscInitializeNoArguments(); code != 0)
            throw AlgorithmError("PETSc: initialisation failed (error " + std::to_string(code) +
                                 "); MPI may be unable to start as a singleton here");
        owned_ = true;
        PetscPopSignalHandler();
        PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
    }
    ~PetscRuntime() {
        if (!owned_) return;
        PetscBool finalized = PETSC_FALSE;
        PetscFinalized(&finalized);
        if (!finalized) PetscFinalize();
    }
    PetscRuntime(const PetscRuntime&) = delete;
    PetscRuntime& operator=(const PetscRuntime&) = delete;

private:
    bool owned_ = false;
};

}  // namespace

void ensure_petsc_runtime() {
    // A function-local static: constructed once (thread safe), destroyed at exit after every object
    // that was created after it, so PETSc objects owned by statics created later are freed first.
    static const PetscRuntime runtime;
}

}  // namespace waxwork
