// The process's peak memory: what the scaling measurements (`render --engine petsc`'s summary) report
// per process.
#pragma once

namespace waxwork {

// Peak resident set size of this process so far, in MiB (getrusage's ru_maxrss); 0 where unknown.
double peak_resident_mib();

}  // namespace waxwork
