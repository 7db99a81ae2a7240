#include "solver/petsc_runtime.h"

#include "base/error.h"

#include <petscsys.h>

#include <exception>
#include <limits>
#include <string>
#include <vector>

namespace waxwork {
namespace {

class PetscRuntime {
public:
    // argc and argv, when given, must outlive PETSc (it keeps them: PetscGetArgs).
    PetscRuntime(int* argc, char*** argv) {
        PetscBool initialized = PETSC_FALSE;
        if (PetscInitialized(&initialized) != 0)
            throw AlgorithmError("PETSc: cannot query whether it is initialised");
        if (initialized) return;  // the program's own PetscInitialize: its finalisation too
        const PetscErrorCode code = argc ? PetscInitialize(argc, argv, nullptr, nullptr) : PetscInitializeNoArguments();
        if (code != 0)
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

// A function-local static: constructed once (thread safe) by the first caller, with its arguments, and
// destroyed at exit after every object that was created after it, so PETSc objects owned by statics
// created later are freed first.
void start_runtime(int* argc, char*** argv) { static const PetscRuntime runtime(argc, argv); }

}  // namespace

void ensure_petsc_runtime() { start_runtime(nullptr, nullptr); }

void ensure_petsc_runtime(int argc, char** argv) {
    static int kept_argc = argc;
    static char** kept_argv = argv;
    start_runtime(&kept_argc, &kept_argv);
}

void check_petsc(int code, const char* call) {
    if (code == 0) return;
    const char* text = nullptr;
    PetscErrorMessage(static_cast<PetscErrorCode>(code), &text, nullptr);
    throw AlgorithmError(std::string("PETSc: ") + call + " failed (" + (text ? text : "error") + ", code " +
                         std::to_string(code) + ")");
}

PetscProcesses petsc_processes() {
    ensure_petsc_runtime();
    PetscProcesses processes;
    if (MPI_Comm_rank(PETSC_COMM_WORLD, &processes.rank) != MPI_SUCCESS ||
        MPI_Comm_size(PETSC_COMM_WORLD, &processes.size) != MPI_SUCCESS)
        throw AlgorithmError("MPI: cannot query this process's rank");
    return processes;
}

namespace {

template <typename T>
void broadcast(std::vector<T>& values, MPI_Datatype type) {
    if (values.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
        throw AlgorithmError("MPI: " + std::to_string(values.size()) + " values are too many for one broadcast");
    int count = static_cast<int>(values.size());
    if (MPI_Bcast(&count, 1, MPI_INT, 0, PETSC_COMM_WORLD) != MPI_SUCCESS)
        throw AlgorithmError("MPI: a broadcast failed");
    values.resize(static_cast<size_t>(count));
    if (MPI_Bcast(values.data(), count, type, 0, PETSC_COMM_WORLD) != MPI_SUCCESS)
        throw AlgorithmError("MPI: a broadcast failed");
}

}  // namespace

void broadcast_from_rank0(std::vector<double>& values) { broadcast(values, MPI_DOUBLE); }
void broadcast_from_rank0(std::vector<int32_t>& values) { broadcast(values, MPI_INT32_T); }

std::vector<int64_t> gather_from_all(int64_t value) {
    std::vector<int64_t> values(static_cast<size_t>(petsc_processes().size));
    if (MPI_Allgather(&value, 1, MPI_INT64_T, values.data(), 1, MPI_INT64_T, PETSC_COMM_WORLD) != MPI_SUCCESS)
        throw AlgorithmError("MPI: gathering a value from every process failed");
    return values;
}

void agreed_step(const std::function<void()>& step) {
    const PetscProcesses processes = petsc_processes();
    std::exception_ptr failure;
    std::string message;
    try {
        step();
    } catch (const std::exception& e) {
        failure = std::current_exception();
        message = e.what();
    }
    // The lowest failing rank, or size when none failed.
    const int mine = failure ? processes.rank : processes.size;
    int lowest = processes.size;
    if (MPI_Allreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD) != MPI_SUCCESS)
        throw AlgorithmError("MPI: the processes could not agree on the outcome of a step");
    if (lowest == processes.size) return;
    int length = static_cast<int>(message.size());
    MPI_Bcast(&length, 1, MPI_INT, lowest, PETSC_COMM_WORLD);
    std::vector<char> text(message.begin(), message.end());
    text.resize(static_cast<size_t>(length));
    MPI_Bcast(text.data(), length, MPI_CHAR, lowest, PETSC_COMM_WORLD);
    if (processes.rank == lowest) std::rethrow_exception(failure);
    // The rank that failed, when it is not the one that prints (rank 0).
    throw Error(std::string(text.begin(), text.end()) + " (process " + std::to_string(lowest) + " of " +
                std::to_string(processes.size) + ")");
}

}  // namespace waxwork
