// The documents that describe the source tree keep up with it: every folder directly under src/
// has a row in README.md's folder table (rows of the form "| `src/NAME` | what |") and a line in
// the layout of docs/architecture.md ("src/NAME/"), and neither names a folder that is gone.
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
    std::ifstream in(p);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::set<std::string> src_folders() {
    std::set<std::string> out;
    for (const fs::directory_entry& e : fs::directory_iterator(fs::path(CANDELA_SOURCE_DIR) / "src"))
        if (e.is_directory()) out.insert(e.path().filename().string());
    return out;
}

// The folders named in the first cell of README's table rows: "| `src/a` |" or "| `src/a`, `src/b` |".
std::set<std::string> readme_table_folders(const std::string& readme) {
    std::set<std::string> out;
    std::istringstream lines(readme);
    std::string line;
    while (std::getline(lines, line)) {
        if (line.rfind("| `src/", 0) != 0) continue;
        const size_t cell_end = line.find(" |", 1);
        const std::string cell = line.substr(1, cell_end == std::string::npos ? std::string::npos : cell_end - 1);
        for (size_t at = cell.find("`src/"); at != std::string::npos; at = cell.find("`src/", at + 1)) {
            const size_t close = cell.find('`', at + 1);
            if (close != std::string::npos) out.insert(cell.substr(at + 5, close - at - 5));
        }
    }
    return out;
}

// The folders of docs/architecture.md's layout block: lines that start with "src/NAME/".
std::set<std::string> architecture_layout_folders(const std::string& doc) {
    std::set<std::string> out;
    std::istringstream lines(doc);
    std::string line;
    while (std::getline(lines, line)) {
        if (line.rfind("src/", 0) != 0) continue;
        const size_t slash = line.find('/', 4);
        if (slash != std::string::npos) out.insert(line.substr(4, slash - 4));
    }
    return out;
}

}  // namespace

TEST(Docs, ReadmeFolderTableHasEverySrcFolder) {
    const std::string readme = read_text(fs::path(CANDELA_SOURCE_DIR) / "README.md");
    ASSERT_FALSE(readme.empty()) << "README.md";
    const std::set<std::string> rows = readme_table_folders(readme), folders = src_folders();
    ASSERT_GE(folders.size(), 10u);
    for (const std::string& f : folders) EXPECT_EQ(rows.count(f), 1u) << "README.md's folder table has no row for src/" << f;
    for (const std::string& r : rows) EXPECT_EQ(folders.count(r), 1u) << "README.md's folder table names src/" << r << ", which does not exist";
}

TEST(Docs, ArchitectureLayoutHasEverySrcFolder) {
    const std::string doc = read_text(fs::path(CANDELA_SOURCE_DIR) / "docs" / "architecture.md");
    ASSERT_FALSE(doc.empty()) << "docs/architecture.md";
    const std::set<std::string> listed = architecture_layout_folders(doc), folders = src_folders();
    for (const std::string& f : folders) EXPECT_EQ(listed.count(f), 1u) << "docs/architecture.md's layout does not list src/" << f;
    for (const std::string& l : listed) EXPECT_EQ(folders.count(l), 1u) << "docs/architecture.md's layout lists src/" << l << ", which does not exist";
}

// The parsing itself: a table without a row is caught (the check above cannot pass vacuously).
TEST(Docs, MissingRowIsFound) {
    const std::string table = "| folder | what |\n|---|---|\n| `src/core` | x |\n| `src/display`, `src/headless` | y |\n";
    const std::set<std::string> rows = readme_table_folders(table);
    EXPECT_EQ(rows, (std::set<std::string>{"core", "display", "headless"}));
    EXPECT_EQ(architecture_layout_folders("```\nsrc/core/   a\n                 b\nsrc/film/   c\n```\n"),
              (std::set<std::string>{"core", "film"}));
}
