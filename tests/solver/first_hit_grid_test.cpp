// The first-hit grid against a brute-force search over every triangle.
#include "base/error.h"
#include "solver/reference/first_hit_grid.h"
#include "tetops/icosphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace waxwork {
namespace {

TEST(FirstHitGrid, FindsTheNearestTriangleAsBruteForceDoes) {
    // Two spheres, one behind the other, and rays from everywhere around: the nearest hit must be the
    // front sphere's where both are in the way.
    std::vector<Eigen::Vector3d> points;
    std::vector<std::array<int32_t, 3>> triangles;
    for (const Eigen::Vector3d& centre : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.5, 0.2, -3)}) {
        const TriangleSurface sphere = make_icosphere(2, 1.0);
        const int32_t base = static_cast<int32_t>(points.size());
        for (const Eigen::Vector3d& p : sphere.points) points.push_back(centre + p);
        for (const auto& t : sphere.triangles) triangles.push_back({base + t[0], base + t[1], base + t[2]});
    }
    const FirstHitGrid grid(points, triangles);
    std::mt19937 random(5);
    std::uniform_real_distribution<double> uniform(-1, 1);
    int hits = 0;
    for (int ray = 0; ray < 2000; ++ray) {
        const Eigen::Vector3d origin(4 * uniform(random), 4 * uniform(random), 3 + 2 * uniform(random));
        const Eigen::Vector3d target(uniform(random), uniform(random), -1.5 + 2 * uniform(random));
        const Eigen::Vector3d direction = (target - origin).normalized();
        double nearest = std::numeric_limits<double>::infinity();
        int32_t which = -1;
        for (size_t t = 0; t < triangles.size(); ++t) {
            const Eigen::Vector3d& a = points[triangles[t][0]];
            const Eigen::Vector3d n = (points[triangles[t][1]] - a).cross(points[triangles[t][2]] - a);
            const double along = n.dot(direction);
            if (along == 0) continue;
            const double s = n.dot(a - origin) / along;
            if (!(s > 0)) continue;
            const Eigen::Vector3d p = origin + s * direction;
            bool inside = true;
            for (int k = 0; k < 3; ++k) {
                const Eigen::Vector3d& u = points[triangles[t][k]];
                const Eigen::Vector3d& v = points[triangles[t][(k + 1) % 3]];
                inside = inside && (v - u).cross(p - u).dot(n) >= 0;
            }
            if (inside && s < nearest) {
                nearest = s;
                which = static_cast<int32_t>(t);
            }
        }
        const auto hit = grid.first_hit(origin, direction);
        ASSERT_EQ(hit.has_value(), which >= 0) << "ray " << ray;
        if (!hit) continue;
        ++hits;
        EXPECT_NEAR(hit->t, nearest, 1e-9) << "ray " << ray;
        const auto& tri = triangles[hit->triangle];
        const Eigen::Vector3d p = (1 - hit->u - hit->v) * points[tri[0]] + hit->u * points[tri[1]] + hit->v * points[tri[2]];
        EXPECT_LT((p - (origin + nearest * direction)).norm(), 1e-9) << "ray " << ray;
    }
    EXPECT_GT(hits, 500);
    EXPECT_THROW(FirstHitGrid(points, {{0, 1, static_cast<int32_t>(points.size())}}), InvalidArgumentError);
}

}  // namespace
}  // namespace waxwork
