// The editor's window-free pieces: directory listing for the file dialog, material swatches and the
// background task.
#include "editor/background_task.h"
#include "editor/file_dialog.h"
#include "editor/material_swatch.h"
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

}  // namespace
}  // namespace waxwork
