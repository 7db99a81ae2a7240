// Where the seeds' methods fail (bench/studies/method_failures.h): each table shows what it claims.
#include "bench/studies/method_failures.h"

#include <gtest/gtest.h>

#include <string>

namespace waxwork {
namespace {

std::string text(const nlohmann::json& cell) { return cell.is_string() ? cell.get<std::string>() : cell.dump(); }

size_t column(const StudyTable& table, const std::string& name) {
    for (size_t c = 0; c < table.columns.size(); ++c)
        if (table.columns[c] == name) return c;
    ADD_FAILURE() << table.name << ": no column " << name;
    return 0;
}

TEST(MethodFailures, FvmKeptFailsOnSliversAndClampedConverges) {
    const StudyTable table = study_fvm_non_delaunay({.quick = true});
    ASSERT_EQ(table.rows.size(), 2u);
    const auto& slivers = table.rows.back();
    EXPECT_NE(text(slivers[column(table, "kept_relaxation")]).find("fails"), std::string::npos);
    EXPECT_NE(text(slivers[column(table, "kept_cg")]).find("fails"), std::string::npos);
    EXPECT_EQ(text(slivers[column(table, "clamped_error")]).find("fails"), std::string::npos);
    EXPECT_NE(table.to_markdown().find("fvm on a non-Delaunay mesh"), std::string::npos);
}

TEST(MethodFailures, FdSolvesCracksAndWarnsAboutPartsThinnerThanACell) {
    const StudyTable table = study_fd_cuts({.quick = true});
    const size_t outcome = column(table, "outcome"), warnings = column(table, "warnings"), cell = column(table, "cell_mm");
    bool warned_coarse = false, clean_fine = false, error_alone = false, cracked_clean = false;
    for (const auto& row : table.rows) {
        const std::string what = text(row[0]);
        if (what.find("broken") != std::string::npos) cracked_clean = text(row[outcome]) == "solved" && text(row[warnings]).empty();
        if (what.find("plate") != std::string::npos && row[cell].get<double>() == 0.5)
            warned_coarse = text(row[warnings]).find("thinner than a cell") != std::string::npos;
        if (what.find("plate") != std::string::npos && row[cell].get<double>() == 0.1) clean_fine = text(row[warnings]).empty();
        if (what.find("alone") != std::string::npos) error_alone = text(row[outcome]).find("error: fd:") == 0;
    }
    EXPECT_TRUE(cracked_clean);
    EXPECT_TRUE(warned_coarse);
    EXPECT_TRUE(clean_fine);
    EXPECT_TRUE(error_alone);
}

TEST(MethodFailures, LbmRefusesTauAtOneHalfAndWarnsOutsideItsRange) {
    const StudyTable table = study_lbm_relaxation({.quick = true});
    const size_t outcome = column(table, "outcome"), warnings = column(table, "warnings");
    for (const auto& row : table.rows) {
        const std::string what = text(row[0]);
        if (what == "tau 0.45") {
            EXPECT_NE(text(row[outcome]).find("error: lbm: tau"), std::string::npos);
        }
        if (what == "tau 1") {
            EXPECT_EQ(text(row[outcome]), "converged");
        }
        if (what == "tau 4") {
            EXPECT_NE(text(row[warnings]).find("tau 4 > 2"), std::string::npos) << text(row[warnings]);
        }
        if (what == "mu_a 0.5, tau 1, implicit absorption") {
            EXPECT_EQ(text(row[outcome]), "converged");
        }
    }
}

TEST(MethodFailures, DipoleIsTooDarkBehindThinSlabsAndWarns) {
    const StudyTable table = study_dipole_thin_parts({.quick = true});
    ASSERT_EQ(table.rows.size(), 2u);
    for (const auto& row : table.rows) {
        EXPECT_LT(row[column(table, "unlit_dipole_over_transcut")].get<double>(), 0.85);
        EXPECT_NE(text(row[column(table, "warning")]).find("thinner than"), std::string::npos);
    }
}

}  // namespace
}  // namespace waxwork
