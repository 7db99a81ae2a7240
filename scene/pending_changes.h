// What changed since one copy of the live system last caught up. Each copy a frame solver keeps (the
// multigrid frame solver, the multires hierarchy, the device) applies its own record at its next
// frame, so a change reaches every copy exactly once whichever of them runs when.
#pragma once

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <span>
#include <vector>

namespace waxwork {

struct PendingChanges {
    bool all_values = false;    // every matrix value changed (same pattern); rows is then empty
    std::vector<int32_t> rows;  // else the rows that changed, ascending and unique
    bool right_hand_sides = true;
    bool solution = true;  // the host phi was replaced (or never sent): start from it

    void values_changed() {
        all_values = true;
        rows.clear();
    }
    // Adds ascending, unique rows; nothing to add after all_values (every row is re-sent anyway).
    void rows_changed(std::span<const int32_t> ascending_unique) {
        if (all_values) return;
        std::vector<int32_t> merged;
        merged.reserve(rows.size() + ascending_unique.size());
        std::set_union(rows.begin(), rows.end(), ascending_unique.begin(), ascending_unique.end(),
                       std::back_inserter(merged));
        rows.swap(merged);
    }
    void values_applied() {
        all_values = false;
        rows.clear();
    }
};

}  // namespace waxwork
