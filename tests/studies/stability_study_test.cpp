// The stability studies (bench/studies/stability_study.h) on their quick sizes: each table must show the
// behaviour its "what Waxwork does" claims.
#include "bench/studies/stability_study.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace waxwork {
namespace {

using Json = nlohmann::json;

// Column name -> cell of one row.
std::map<std::string, Json> cells(const StudyTable& table, size_t row) {
    std::map<std::string, Json> out;
    for (size_t c = 0; c < table.columns.size(); ++c) out[table.columns[c]] = table.rows[row][c];
    return out;
}

bool converged(const std::map<std::string, Json>& row) { return row.at("outcome").get<std::string>() == "converged"; }

TEST(StabilityStudy, SliversConvergeInDoubleAndFloatNeverReturnsGarbage) {
    const StudyTable table = study_slivers({.quick = true});
    double smallest_angle = 180, largest_angle = 0;
    for (size_t r = 0; r < table.rows.size(); ++r) {
        const auto row = cells(table, r);
        smallest_angle = std::min(smallest_angle, row.at("min_dihedral_deg").get<double>());
        largest_angle = std::max(largest_angle, row.at("min_dihedral_deg").get<double>());
        if (row.at("precision") == "double") {
            EXPECT_TRUE(converged(row)) << row.at("outcome");
            EXPECT_LT(row.at("rel_error").get<double>(), 1e-3);
        } else if (converged(row)) {
            // Float either reaches the tolerance or says it cannot: a converged float solve is accurate.
            EXPECT_LT(row.at("rel_error").get<double>(), 1e-2);
        } else {
            EXPECT_EQ(row.at("outcome").get<std::string>().rfind("error: ", 0), 0u);
        }
    }
    EXPECT_LT(smallest_angle, 0.05);  // the sweep reaches the sliver range it claims
    EXPECT_GT(largest_angle, 1.0);
}

TEST(StabilityStudy, RelaxationGuardKeepsAnglesAboveHalfADegree) {
    const StudyTable table = study_relaxation_guard({.quick = true});
    double guarded = -1, unguarded = -1;
    for (size_t r = 0; r < table.rows.size(); ++r) {
        const auto row = cells(table, r);
        (row.at("guard_deg").get<double>() > 0 ? guarded : unguarded) = row.at("min_dihedral_deg").get<double>();
        if (row.at("guard_deg").get<double>() > 0) {
            EXPECT_EQ(row.at("tets_under_0.5deg").get<int>(), 0);
            if (row.at("precision") == "double") {
                EXPECT_TRUE(converged(row));
            }
        }
    }
    EXPECT_GE(guarded, 0.5);
    EXPECT_LT(unguarded, 0.5);  // without the guard relaxation squeezes tets flat (Fig. 9a)
}

TEST(StabilityStudy, MaterialExtremes) {
    const StudyTable table = study_material_extremes({.quick = true});
    std::map<std::string, double> error;
    for (size_t r = 0; r < table.rows.size(); ++r) {
        const auto row = cells(table, r);
        EXPECT_TRUE(converged(row)) << row.at("material");
        error[row.at("material").get<std::string>()] = row.at("rel_error_vs_exact").get<double>();
    }
    EXPECT_LT(error.at("spectralon"), 1e-6);  // the exact solution is a constant: linear elements hold it
    EXPECT_LT(error.at("marble"), 0.02);
    EXPECT_GT(error.at("ketchup"), error.at("marble"));  // the under-resolved boundary layer
}

TEST(StabilityStudy, ThinPartsStayStableAndConverge) {
    const StudyTable table = study_thin_parts({.quick = true});
    // error[mean free path][thickness in tets]
    std::map<double, std::map<int, double>> error;
    for (size_t r = 0; r < table.rows.size(); ++r) {
        const auto row = cells(table, r);
        EXPECT_TRUE(converged(row));
        error[row.at("mean_free_path_mm").get<double>()][row.at("thickness_tets").get<int>()] =
            row.at("rel_error_vs_refined").get<double>();
    }
    ASSERT_EQ(error.size(), 3u);
    for (const auto& [mfp, by_thickness] : error)  // more tets across a part: smaller error
        EXPECT_LT(by_thickness.at(2), by_thickness.at(1)) << "mean free path " << mfp;
}

TEST(StabilityStudy, ErrorEstimateBoundsTheTrueErrorUnderKappaContrast) {
    const StudyTable table = study_kappa_contrast({.quick = true});
    double largest_ratio = 0;
    for (size_t r = 0; r < table.rows.size(); ++r) {
        const auto row = cells(table, r);
        if (row.at("precision") != "double") continue;
        EXPECT_TRUE(converged(row));
        EXPECT_TRUE(row.at("estimate_bounds_true").get<bool>()) << "kappa ratio " << row.at("kappa_ratio");
        largest_ratio = std::max(largest_ratio, row.at("kappa_ratio").get<double>());
    }
    EXPECT_GT(largest_ratio, 900);
}

TEST(StabilityStudy, CoarseBreakdownFallsBackAndStaysAccurate) {
    const StudyTable table = study_coarse_breakdown({.quick = true});
    ASSERT_EQ(table.rows.size(), 5u);
    for (size_t r = 0; r < table.rows.size(); ++r) {
        const auto row = cells(table, r);
        EXPECT_TRUE(row.at("finite").get<bool>()) << row.at("fault");
        EXPECT_LT(row.at("rel_error").get<double>(), 1e-4) << row.at("fault");
        // A singular or non-finite level must be skipped; a negated or rank-deficient one may still
        // give BiCGSTAB a usable (if poor) iterate, which the fine CG then corrects.
        const std::string fault = row.at("fault");
        if (fault.find("singular") != std::string::npos || fault.find("NaN") != std::string::npos) {
            EXPECT_GE(row.at("fallbacks").get<int>(), 1) << fault;
            EXPECT_NE(row.at("reasons").get<std::string>(), "-");
        }
    }
}

TEST(StabilityStudy, MultigridOnSliversFallsBackToAbsoluteLumpingAndConverges) {
    const StudyTable table = study_multigrid_slivers({.quick = true});
    ASSERT_FALSE(table.rows.empty());
    int row_sum_failures = 0;
    for (size_t r = 0; r < table.rows.size(); ++r) {
        const auto row = cells(table, r);
        EXPECT_TRUE(converged(row)) << row.at("outcome");
        EXPECT_LT(row.at("rel_error").get<double>(), 1e-4);
        const bool failed = row.at("row_sum_setup").get<std::string>().rfind("error: ", 0) == 0;
        row_sum_failures += failed ? 1 : 0;
        // The fallback is taken exactly when the row-sum setup fails.
        EXPECT_EQ(row.at("lumping").get<std::string>(), failed ? "absolute" : "row-sum");
    }
    EXPECT_GT(row_sum_failures, 0);  // the sweep reaches the case it is about
}

TEST(StabilityStudy, TablesRenderAsJsonAndMarkdown) {
    StudyTable table;
    table.name = "t";
    table.columns = {"a", "b"};
    table.rows = {{1, 0.5}, {"x", nullptr}};
    EXPECT_EQ(table.to_json()["rows"][1][1], nullptr);
    const std::string md = table.to_markdown();
    EXPECT_NE(md.find("| a | b |"), std::string::npos);
    EXPECT_NE(md.find("| x | - |"), std::string::npos);
    EXPECT_NE(md.find("| 1 | 0.5 |"), std::string::npos);
}

}  // namespace
}  // namespace waxwork
