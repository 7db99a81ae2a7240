// Turns a frame's time budget into an iteration count for a solver that cannot check a clock between
// iterations: the GPU backends, whose iterations are queued on the device and whose results come back
// only with the read-back at the end of the frame (stopping a queued solve part-way would need a
// round trip per iteration, which costs more than the iterations on small meshes).
//
// Model: the milliseconds a frame costs per iteration, as an exponential moving average over the
// frames measured so far (the smoothing weight of the newest frame). The frame time also holds what
// does not scale with iterations (uploading changed right-hand sides, reading phi back: O ms), so a
// frame of k iterations of c ms measures (O + k c) / k per iteration. The prediction k' = B k / (O + k c)
// for a budget B still settles where O + k c = B, i.e. on the k that fills the budget exactly (or on one
// iteration when O alone exceeds B: the budget cannot be met, bench/live_solver_bench.cpp shows this
// for llvmpipe at 100K tets). A two-parameter fit would find the same point; this needs one number.
// Frames that did one-off work (a first upload of the matrix, a coarse-to-fine pass) should not be
// recorded: they would make the next frames far too short.
//
// Before any frame was measured the prediction is the budget's iteration limit, or
// kDefaultFirstFrameIterations without one (the editor's default "iterations / frame").
#pragma once

#include "solver/frame_budget.h"

#include <optional>

namespace waxwork {

class IterationTimePredictor {
public:
    static constexpr int kDefaultFirstFrameIterations = 10;
    // A bound on predictions without an iteration limit (a 1000 ms budget on a tiny mesh does not
    // queue millions of iterations; a converged solve stops long before anyway).
    static constexpr int kMaxPredictedIterations = 10000;

    // smoothing in (0, 1]: weight of the newest frame (1: only the last frame counts). Throws
    // InvalidArgumentError outside that range.
    explicit IterationTimePredictor(double smoothing = 0.3);

    // Iterations to queue for a frame of `budget` (validated): its iteration limit when it has no time
    // limit; otherwise floor(max_milliseconds / ms per iteration), at least 1, at most the iteration
    // limit (or kMaxPredictedIterations).
    int iterations_for(const FrameBudget& budget) const;
    // A frame ran `iterations` in `milliseconds`. Ignored unless iterations > 0 and milliseconds is
    // finite and >= 0 (a frame without iterations says nothing about their cost).
    void record(int iterations, double milliseconds);
    // The current estimate; nullopt before the first recorded frame.
    std::optional<double> milliseconds_per_iteration() const { return ms_per_iteration_; }
    void reset() { ms_per_iteration_.reset(); }

private:
    double smoothing_;
    std::optional<double> ms_per_iteration_;
};

}  // namespace waxwork
