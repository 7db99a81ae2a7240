#include "tetops/cgal_mesher.h"

#include "base/error.h"
#include "base/progress.h"
#include "tetops/mesher_scale.h"
#include "tetops/sharp_tips.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_polyhedron_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Random.h>
#include <CGAL/Mesh_error_code.h>
#include <CGAL/exude_mesh_3.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/perturb_mesh_3.h>

#include <algorithm>
#include <unordered_map>

namespace waxwork {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polyhedron = CGAL::Mesh_polyhedron_3<Kernel>::type;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<Kernel, Polyhedron>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using Complex = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

// Mesh_3's criteria bound circumradii (cells), Delaunay-ball radii (facets) and protecting-ball
// spacing (edges); these map a wanted mean edge length onto them (a regular tet's circumradius is
// 0.61 L, an equilateral triangle's 0.58 L; refinement stops below the bound, hence the larger factors).
constexpr double kCellSizePerEdge = 0.9;
constexpr double kFacetSizePerEdge = 0.8;
constexpr double kEdgeSizePerEdge = 1.0;
// The most protection work a tip may make (sharp_tip_work: 495 took 24 s, the time growing like the
// work to the power 2.5 above that).
constexpr double kMaxSharpTipWork = 500;
// Surface approximation error relative to the local edge length.
constexpr double kFacetDistancePerEdge = 0.1;

// A Mesh_3 sizing field: `factor` times edge(depth), the depth measured with an AABB tree.
struct GradedSize {
    const SizeField* field;
    const SurfaceDistance* distance;
    double factor;

    Kernel::FT operator()(const Kernel::Point_3& p, int, const Domain::Index&) const {
        return factor * field->edge_at_depth((*distance)(Eigen::Vector3d(p.x(), p.y(), p.z())));
    }
};

// Refuses, before any work, a surface with a tip CGAL's protection of sharp edges would take minutes
// to hours over (sharp_tips.h).
void refuse_needle_tips(const TriangleSurface& surface, double edge) {
    const std::vector<SharpTip> tips = sharp_tips(surface);
    const auto hardest = std::max_element(tips.begin(), tips.end(), [&](const SharpTip& a, const SharpTip& b) {
        return sharp_tip_work(a, edge) < sharp_tip_work(b, edge);
    });
    if (hardest == tips.end() || !(sharp_tip_work(*hardest, edge) > kMaxSharpTipWork)) return;
    const Eigen::Vector3d& p = surface.points[hardest->vertex];
    throw AlgorithmError("CGAL Mesh_3 cannot mesh this surface in bounded time: two sharp edges " +
                         number_text(hardest->shorter_edge / edge) + " mesh edges long meet at " +
                         number_text(hardest->angle_deg) + " degrees at point " + std::to_string(hardest->vertex) +
                         " (" + number_text(p.x()) + ", " + number_text(p.y()) + ", " + number_text(p.z()) +
                         "), a needle its protection of sharp edges would take minutes to hours over; use the "
                         "TetGen mesher (--mesher tetgen), which keeps the surface's triangles");
}

Polyhedron to_polyhedron(const TriangleSurface& surface) {
    std::vector<Kernel::Point_3> points;
    points.reserve(surface.points.size());
    for (const auto& p : surface.points) points.emplace_back(p.x(), p.y(), p.z());
    std::vector<std::array<size_t, 3>> polygons;
    polygons.reserve(surface.triangles.size());
    for (const auto& t : surface.triangles) polygons.push_back({size_t(t[0]), size_t(t[1]), size_t(t[2])});
    if (!CGAL::Polygon_mesh_processing::is_polygon_soup_a_polygon_mesh(polygons)) {
        throw InvalidMeshError("CGAL mesher: the surface is not a manifold polygon mesh");
    }
    Polyhedron polyhedron;
    CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(points, polygons, polyhedron);
    return polyhedron;
}

TetMesh to_tet_mesh(const Complex& complex) {
    std::unordered_map<Triangulation::Vertex_handle, int32_t> index;
    std::vector<Eigen::Vector3d> positions;
    std::vector<Tet> tets;
    tets.reserve(complex.number_of_cells_in_complex());
    for (auto cell = complex.cells_in_complex_begin(); cell != complex.cells_in_complex_end(); ++cell) {
        Tet tet;
        for (int k = 0; k < 4; ++k) {
            const auto vertex = cell->vertex(k);
            auto [it, inserted] = index.emplace(vertex, static_cast<int32_t>(positions.size()));
            if (inserted) {
                const auto& p = vertex->point().point();
                positions.emplace_back(p.x(), p.y(), p.z());
            }
            tet[k] = it->second;
        }
        // Triangulation_3 cells are positively oriented (CGAL::orientation == POSITIVE), which is
        // Waxwork's convention; checked anyway, the cost is nothing next to meshing.
        if (signed_volume(positions[tet[0]], positions[tet[1]], positions[tet[2]], positions[tet[3]]) < 0) {
            std::swap(tet[2], tet[3]);
        }
        tets.push_back(tet);
    }
    if (tets.empty()) throw AlgorithmError("CGAL Mesh_3 produced no tetrahedra");
    return make_tet_mesh(std::move(positions), std::move(tets));
}

}  // namespace

TetMesh cgal_tetrahedralize(const TriangleSurface& surface, const CgalSettings& settings) {
    if (const int exponent = mesher_scale_exponent(surface); exponent != 0) {
        CgalSettings scaled = settings;
        scaled.size = scaled_size_field(settings.size, exponent);
        TetMesh mesh = cgal_tetrahedralize(scaled_surface(surface, exponent), scaled);
        scale_positions(mesh, -exponent);
        return mesh;
    }
    SizeField size = settings.size;
    if (!size.is_bounded()) {
        // Mesh_3 needs a size bound to terminate; a twentieth of the bounding-box diagonal is coarse.
        Eigen::AlignedBox3d box;
        for (const auto& p : surface.points) box.extend(p);
        size = SizeField::uniform(box.diagonal().norm() / 20);
    }
    refuse_needle_tips(surface, size.surface_edge);
    try {
        report_stage(settings.progress, "meshing (CGAL, surface domain)");
        // Seeded generators: the domain's initial points and the exuder draw from them.
        CGAL::get_default_random() = CGAL::Random(0);
        CGAL::Random domain_random(0);
        Domain domain(to_polyhedron(surface), &domain_random);
        domain.detect_features();

        const SurfaceDistance distance(surface);
        namespace params = CGAL::parameters;
        const Criteria criteria(
            params::edge_size = GradedSize{&size, &distance, kEdgeSizePerEdge},
            params::facet_angle = 25,
            params::facet_size = GradedSize{&size, &distance, kFacetSizePerEdge},
            params::facet_distance = kFacetDistancePerEdge * size.surface_edge,
            params::cell_radius_edge_ratio = std::max(settings.max_radius_edge_ratio, 2.0),
            params::cell_size = GradedSize{&size, &distance, kCellSizePerEdge});
        // Refinement first, with Mesh_3's bound on its vertices and the cancel flag (both also stop
        // the sharp-edge protection), then the sliver perturber and exuder, both towards the sliver
        // bound and without a time limit, so that the mesh does not depend on the machine's speed.
        report_stage(settings.progress, "meshing (CGAL)");
        CGAL::Mesh_error_code error = CGAL::CGAL_MESH_3_NO_ERROR;
        Complex complex = CGAL::make_mesh_3<Complex>(
            domain, criteria, params::no_perturb(), params::no_exude(),
            params::mesh_3_options(params::maximal_number_of_vertices = settings.max_vertices,
                                   params::pointer_to_error_code = &error,
                                   params::pointer_to_stop_atomic_boolean =
                                       settings.progress ? settings.progress->cancel_flag() : nullptr));
        if (error == CGAL::CGAL_MESH_3_STOPPED) settings.progress->throw_if_cancelled();
        if (error == CGAL::CGAL_MESH_3_MAXIMAL_NUMBER_OF_VERTICES_REACHED)
            throw AlgorithmError("CGAL Mesh_3 stopped at its limit of " + std::to_string(settings.max_vertices) +
                                 " vertices, where this size needs about " +
                                 std::to_string(settings.predicted_vertices) +
                                 ": sharp features meeting at a small angle (a needle-like or very thin "
                                 "part) make its refinement go on without end; use the TetGen mesher "
                                 "(--mesher tetgen), which keeps the surface's triangles");
        check_cancelled(settings.progress);
        report_stage(settings.progress, "perturbing slivers (CGAL)");
        CGAL::perturb_mesh_3(complex, domain, params::time_limit = 0,
                             params::sliver_bound = settings.min_dihedral_deg);
        check_cancelled(settings.progress);
        report_stage(settings.progress, "exuding slivers (CGAL)");
        CGAL::exude_mesh_3(complex, params::time_limit = 0, params::sliver_bound = settings.min_dihedral_deg);
        return to_tet_mesh(complex);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw AlgorithmError(std::string("CGAL Mesh_3 failed: ") + e.what());
    }
}

}  // namespace waxwork
