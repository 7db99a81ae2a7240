// Where the seeds' methods fail (solver/methods/), each case built on purpose as the stability study
// builds TransCut's (stability_study.h): what fails, how it shows, and what Waxwork does (an error, a
// warning or a clamp). `waxwork bench --only stability` writes them after TransCut's tables;
// tests/studies/method_failures_test.cpp asserts what each table claims.
#pragma once

#include "bench/studies/stability_study.h"

#include <vector>

namespace waxwork {

// fvm on a non-Delaunay mesh: the ball with interior vertices pushed into slivers of decreasing height;
// the circumcentric dual's negative coefficients kept (relaxation and CG) and clamped, against the
// analytic ball, beside TransCut on the same mesh.
StudyTable study_fvm_non_delaunay(const StudySize& size);

// fd on cut volumes: a block with a slot narrower and wider than a voxel, light on one side of it.
StudyTable study_fd_cuts(const StudySize& size);

// lbm with its relaxation time and absorption per step outside the stable range.
StudyTable study_lbm_relaxation(const StudySize& size);

// dipole on slabs thinner than a few diffusion lengths, lit from one side, against TransCut.
StudyTable study_dipole_thin_parts(const StudySize& size);

// All four, in that order.
std::vector<StudyTable> run_method_failure_studies(const StudySize& size);

}  // namespace waxwork
