// The editor's window-free pieces: directory listing for the file dialog, material swatches, the
// background task and the repairs a refused surface's dialog offers.
#include "editor/background_task.h"
#include "editor/file_dialog.h"
#include "editor/material_swatch.h"
#include "editor/repair_choices.h"
#include "solver/material.h"

#include <gtest/gtest.h>

#include <fstream>
#include <thread>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

TEST(FileDialog, ListsDirectoriesFirstThenMatchingFilesSorted) {
    const fs::path dir = fs::temp_directory_path() / ("waxwork_list_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "zeta");
    fs::create_directories(dir / "alpha");
    fs::create_directories(dir / ".hidden_dir");
    for (const char* name : {"b.OBJ", "a.vtu", "c.txt", ".hidden.obj", "d.obj"}) std::ofstream(dir / name) << "x";
    const auto entries = list_directory(dir, {".obj", ".vtu"});
    std::vector<std::string> names;
    for (const auto& e : entries) names.push_back(e.name);
    EXPECT_EQ(names, (std::vector<std::string>{"alpha", "zeta", "a.vtu", "b.OBJ", "d.obj"}));
    EXPECT_TRUE(entries[0].is_directory);
    EXPECT_FALSE(entries[2].is_directory);
    EXPECT_EQ(list_directory(dir, {}).size(), 6u);  // every visible file and directory
    EXPECT_TRUE(list_directory(dir / "missing", {}).empty());
    fs::remove_all(dir);
}

TEST(MaterialSwatch, IsSrgbAndKeepsTheOrderOfTheReflectance) {
    // Ketchup reflects its red far more than its green and blue (solver/material_test.cpp).
    const auto colour = swatch_colour(material_preset("ketchup"));
    EXPECT_GT(colour[0], colour[1]);
    for (float c : colour) {
        EXPECT_GE(c, 0.0f);
        EXPECT_LE(c, 1.0f);
    }
}

TEST(BackgroundTask, RunsOffTheCallingThreadAndAppliesOnPoll) {
    BackgroundTask task;
    int installed = 0;
    std::thread::id worker;
    task.start("work", [&](TaskProgress& progress) {
        worker = std::this_thread::get_id();
        progress.set_stage("halfway");
        progress.set_fraction(0.5f);
        return BackgroundTask::Apply([&installed] { installed = 42; });
    });
    EXPECT_TRUE(task.busy());
    task.wait();
    EXPECT_EQ(installed, 0);  // nothing changes before the UI thread polls
    EXPECT_TRUE(task.poll());
    EXPECT_EQ(installed, 42);
    EXPECT_NE(worker, std::this_thread::get_id());
    EXPECT_FALSE(task.busy());
    EXPECT_FALSE(task.poll());
}

TEST(BackgroundTask, RethrowsTheWorkersErrorOnPoll) {
    BackgroundTask task;
    task.start("failing", [](TaskProgress&) -> BackgroundTask::Apply { throw std::runtime_error("broken"); });
    task.wait();
    EXPECT_THROW(task.poll(), std::runtime_error);
    EXPECT_FALSE(task.busy());
    // A new task may start after a failure; a second start while busy is refused.
    task.start("slow", [](TaskProgress& progress) {
        while (!progress.cancel_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        return BackgroundTask::Apply{};
    });
    EXPECT_THROW(task.start("again", [](TaskProgress&) { return BackgroundTask::Apply{}; }), std::logic_error);
    task.cancel();
    task.wait();
    EXPECT_TRUE(task.poll());
}

TEST(BackgroundTask, RemembersThatCancelWasRequestedUntilTheNextStart) {
    BackgroundTask task;
    EXPECT_FALSE(task.cancel_requested());  // nothing started
    task.start("slow", [](TaskProgress& progress) {
        while (!progress.cancel_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        progress.throw_if_cancelled();
        return BackgroundTask::Apply{};
    });
    EXPECT_FALSE(task.cancel_requested());
    task.cancel();
    EXPECT_TRUE(task.cancel_requested());
    task.wait();
    EXPECT_THROW(task.poll(), CancelledError);
    EXPECT_TRUE(task.cancel_requested());  // still known after the work ended
    task.start("next", [](TaskProgress&) { return BackgroundTask::Apply{}; });
    EXPECT_FALSE(task.cancel_requested());
    task.wait();
    EXPECT_TRUE(task.poll());
}

std::vector<std::string> choice_ids(const std::vector<RepairChoice>& choices) {
    std::vector<std::string> ids;
    for (const RepairChoice& c : choices) ids.push_back(c.id);
    return ids;
}

TEST(RepairChoices, OfferTheHardRepairsThatApplyThenWrapping) {
    SurfaceRepairOptions none;
    none.max_triangles = 500;
    SurfaceDefects open;
    open.boundary_edges = 4;
    const auto holes = repair_choices(open, true, none);
    ASSERT_EQ(choice_ids(holes), (std::vector<std::string>{"fill_holes", "wrap"}));
    EXPECT_TRUE(holes[0].repair.fill_holes);
    EXPECT_FALSE(holes[0].repair.autorefine);
    EXPECT_FALSE(holes[0].repair.wrap);
    EXPECT_EQ(holes[0].repair.max_triangles, 500u);  // the other settings stay
    EXPECT_TRUE(holes[1].repair.wrap);
    EXPECT_FALSE(holes[1].repair.fill_holes);
    EXPECT_EQ(holes[1].repair.max_triangles, 500u);
    EXPECT_EQ(holes[1].label, "Repair by wrapping");

    SurfaceDefects crossing;
    crossing.self_intersecting_pairs = 3;
    EXPECT_EQ(choice_ids(repair_choices(crossing, true, none)), (std::vector<std::string>{"autorefine", "wrap"}));
    crossing.boundary_edges = 2;
    const auto both = repair_choices(crossing, true, none);
    ASSERT_EQ(choice_ids(both), (std::vector<std::string>{"fill_holes_autorefine", "wrap"}));
    EXPECT_TRUE(both[0].repair.fill_holes && both[0].repair.autorefine);
}

TEST(RepairChoices, OnlyWrappingWhereTheHardRepairsCannotStartOrAlreadyRan) {
    SurfaceDefects pinched;
    pinched.boundary_edges = 4;
    pinched.non_manifold_vertices = 1;  // repair_hard_defects refuses non-manifold surfaces
    EXPECT_EQ(choice_ids(repair_choices(pinched, true, {})), (std::vector<std::string>{"wrap"}));
    SurfaceDefects open;
    open.boundary_edges = 4;
    SurfaceRepairOptions filled;
    filled.fill_holes = true;
    EXPECT_EQ(choice_ids(repair_choices(open, true, filled)), (std::vector<std::string>{"wrap"}));
    // Nothing to wrap (missing vertices) and nothing the hard repairs take: no offer.
    SurfaceDefects missing;
    missing.invalid_indices = 1;
    missing.boundary_edges = 3;
    EXPECT_TRUE(repair_choices(missing, false, {}).empty());
}

}  // namespace
}  // namespace waxwork
