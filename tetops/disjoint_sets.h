// Union-find over the indices 0..n-1, with path halving. A union keeps the smaller index as the root,
// so every class's root is its lowest member and the classes and their labels are deterministic
// whatever the order of the unions. Tet components (connectivity.h), fracture pieces (fracture.h)
// and the fans of triangles around a vertex (solver/shading_surface.h) are its classes.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <span>
#include <vector>

namespace waxwork {

class DisjointSets {
public:
    DisjointSets() = default;
    explicit DisjointSets(size_t n) { reset(n); }

    // n singletons again (keeps the storage: one object can serve many small problems).
    void reset(size_t n) {
        parent_.resize(n);
        std::iota(parent_.begin(), parent_.end(), 0);
    }
    size_t size() const { return parent_.size(); }

    int32_t find(int32_t x) {
        while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
        return x;
    }
    void unite(int32_t a, int32_t b) {
        a = find(a), b = find(b);
        if (a != b) parent_[std::max(a, b)] = std::min(a, b);
    }

    // Labels the classes 0, 1, ... in the order of their lowest members into `labels` (size() entries);
    // returns the number of classes.
    int32_t label_classes(std::span<int32_t> labels) {
        int32_t count = 0;
        for (size_t x = 0; x < parent_.size(); ++x) {
            const int32_t root = find(static_cast<int32_t>(x));
            labels[x] = root == static_cast<int32_t>(x) ? count++ : labels[root];  // the root comes first
        }
        return count;
    }

private:
    std::vector<int32_t> parent_;
};

}  // namespace waxwork
