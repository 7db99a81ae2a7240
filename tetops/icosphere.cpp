#include "tetops/icosphere.h"

#include "base/error.h"

#include <cmath>
#include <map>
#include <utility>

namespace waxwork {

TriangleSurface make_icosphere(int level, double radius) {
    if (level < 0 || level > 8) throw InvalidArgumentError("icosphere: subdivision level must be in [0, 8]");
    if (!(radius > 0) || !std::isfinite(radius)) throw InvalidArgumentError("icosphere: radius must be positive");
    const double g = (1.0 + std::sqrt(5.0)) / 2.0;
    TriangleSurface s;
    s.points = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                   {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int l = 0; l < level; ++l) {
        // One new point per edge, shared by the edge's two triangles.
        std::map<std::pair<int32_t, int32_t>, int32_t> midpoints;
        auto midpoint = [&](int32_t a, int32_t b) {
            const auto key = std::minmax(a, b);
            if (auto it = midpoints.find(key); it != midpoints.end()) return it->second;
            s.points.push_back(0.5 * (s.points[a] + s.points[b]));
            const auto id = static_cast<int32_t>(s.points.size() - 1);
            midpoints.emplace(key, id);
            return id;
        };
        std::vector<std::array<int32_t, 3>> next;
        next.reserve(s.triangles.size() * 4);
        for (const auto& t : s.triangles) {
            const int32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
            next.push_back({t[0], ab, ca});
            next.push_back({t[1], bc, ab});
            next.push_back({t[2], ca, bc});
            next.push_back({ab, bc, ca});
        }
        s.triangles = std::move(next);
    }
    for (auto& p : s.points) p = p.normalized() * radius;
    return s;
}

}  // namespace waxwork
