// scripts/test.sh leaves the heaviest tests out of the Debug and sanitizer runs with ctest -E and one
// regular expression each. CMake's regular expressions are not POSIX's: they accept at most nine
// parenthesised groups, and ctest silently excludes nothing when the expression is invalid (this
// happened: a tenth group ran the whole matrix at -O0). These tests give ctest each expression and
// check that it leaves out exactly the tests an ordinary regex engine finds.
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>
#include "support/run.h"

namespace {

namespace fs = std::filesystem;

// The value of NAME='...' in scripts/test.sh.
std::string script_regex(const std::string& name) {
    std::ifstream in(fs::path(CANDELA_SOURCE_DIR) / "scripts" / "test.sh");
    std::string line, key = name + "='";
    while (std::getline(in, line)) {
        const size_t at = line.find(key);
        if (at == std::string::npos) continue;
        const size_t from = at + key.size(), to = line.find('\'', from);
        if (to != std::string::npos) return line.substr(from, to - from);
    }
    return "";
}

// The tests ctest lists in this build, with `-E exclude` when given.
std::vector<std::string> ctest_names(const std::string& exclude) {
    const fs::path build = fs::path(CANDELA_BIN).parent_path().parent_path();
    const std::string cmd = "cd '" + build.string() + "' && ctest -N" + (exclude.empty() ? "" : " -E '" + exclude + "'");
    const candela::test::RunResult r = candela::test::run_shell(cmd);
    std::vector<std::string> names;
    std::istringstream lines(r.output);
    std::string line;
    while (std::getline(lines, line)) {
        const size_t at = line.find(": ");
        if (line.find("Test") != std::string::npos && line.find('#') != std::string::npos && at != std::string::npos)
            names.push_back(line.substr(at + 2));
    }
    return names;
}

void expect_ctest_excludes_as_written(const std::string& exclude) {
    ASSERT_FALSE(exclude.empty());
    const std::vector<std::string> all = ctest_names("");
    ASSERT_GT(all.size(), 100u);
    const std::regex re(exclude, std::regex::extended);
    size_t kept = 0;
    for (const std::string& n : all) kept += std::regex_search(n, re) ? 0 : 1;
    ASSERT_LT(kept, all.size()) << "the expression excludes no test of this build";
    EXPECT_EQ(ctest_names(exclude).size(), kept) << "ctest does not read the expression as written: " << exclude;
}

}  // namespace

TEST(Scripts, DebugExclusionIsReadByCtest) { expect_ctest_excludes_as_written(script_regex("heavy")); }

// As the --sanitize step passes them: the long tests, the power controls and the viewer window.
TEST(Scripts, SanitizerExclusionIsReadByCtest) {
    expect_ctest_excludes_as_written(script_regex("long") + "|" + script_regex("controls") + "|" + script_regex("viewer"));
}
