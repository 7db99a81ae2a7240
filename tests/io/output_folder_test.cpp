#include "base/error.h"
#include "io/output_folder.h"
#include "support/cli_run.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

TEST(OutputFolder, NamesThatCouldEscapeOrMisleadAreRefusedAsText) {
    for (const std::string good : {"a.png", "frames/a.png", "./b.vtu", "x/./y/z.node", "..hidden.vtu"})
        EXPECT_EQ(output_name_problem(good), "") << good;
    const std::pair<std::string, std::string> bad[] = {
        {"", "must not be empty"},
        {"../a.png", "must stay inside the output directory"},
        {"a/../../b.vtu", "must stay inside the output directory"},
        {"/tmp/a.png", "must stay inside the output directory"},
        {std::string("evil.sh\0.vtu", 12), "'evil.sh\\x00.vtu' contains a control character"},
        {"line\nbreak.png", "contains a control character"},
        {"tab\t.png", "contains a control character"},
        {"del\x7f.png", "contains a control character"},
        {"folder/", "names a folder, not a file"},
        {std::string(kMaxSavedFileNameBytes + 1, 'a') + "/b.png", "bytes; at most"},
        {std::string(kMaxSavedFileNameBytes - 3, 'a') + ".png", "bytes; at most"},
    };
    for (const auto& [name, expected] : bad) {
        const std::string problem = output_name_problem(name);
        EXPECT_NE(problem.find(expected), std::string::npos) << name << ": " << problem;
    }
    EXPECT_EQ(output_name_problem(std::string(kMaxSavedFileNameBytes - 4, 'a') + ".png"), "");
}

TEST(OutputFolder, CreatesMissingFoldersInside) {
    const fs::path dir = testing::scratch_dir("output_folder_create");
    EXPECT_EQ(contained_output_path(dir, "a/b/c.png"), dir / "a/b/c.png");
    EXPECT_TRUE(fs::is_directory(dir / "a" / "b"));
    EXPECT_FALSE(fs::exists(dir / "a" / "b" / "c.png"));  // only the folders
}

TEST(OutputFolder, LinksMayLeadInsideButNeverOutside) {
    const fs::path root = testing::scratch_dir("output_folder_links");
    const fs::path out = root / "out", elsewhere = root / "elsewhere";
    fs::create_directories(out / "real");
    fs::create_directories(elsewhere);
    fs::create_directory_symlink(elsewhere, out / "away");
    fs::create_directory_symlink("real", out / "alias");           // relative, stays inside
    fs::create_directory_symlink(out / "real" / "..", out / "up");  // resolves to out itself
    fs::create_directory_symlink(root / "missing", out / "dangling");

    EXPECT_EQ(contained_output_path(out, "alias/new/x.vtu"), out / "alias/new/x.vtu");
    EXPECT_TRUE(fs::is_directory(out / "real" / "new"));
    EXPECT_EQ(contained_output_path(out, "up/y.vtu"), out / "up/y.vtu");
    for (const std::string name : {"away/x.vtu", "away/new/deeper/x.png", "./away/x.vtu"}) {
        try {
            contained_output_path(out, name);
            ADD_FAILURE() << name << " accepted";
        } catch (const FileError& e) {
            EXPECT_EQ(e.path(), (out / "away").string()) << e.what();
            EXPECT_NE(e.problem().find("leads outside the output folder " + out.string() + " (a symbolic link)"),
                      std::string::npos)
                << e.what();
        }
    }
    EXPECT_TRUE(fs::is_empty(elsewhere));  // nothing was created through the link
    try {
        contained_output_path(out, "dangling/x.vtu");
        ADD_FAILURE() << "a dangling link accepted";
    } catch (const FileError& e) {
        EXPECT_EQ(e.path(), (out / "dangling").string()) << e.what();
    }
    EXPECT_FALSE(fs::exists(root / "missing"));
}

TEST(OutputFolder, AFileWhereAFolderShouldBeIsNamed) {
    const fs::path dir = testing::scratch_dir("output_folder_file");
    std::ofstream(dir / "frames") << "not a folder";
    try {
        contained_output_path(dir, "frames/a.png");
        FAIL() << "no error";
    } catch (const FileError& e) {
        EXPECT_EQ(e.path(), (dir / "frames").string());
        EXPECT_NE(e.problem().find("a file of that name exists"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace waxwork
