#pragma once
// Bad scene input is one line naming the file and line: write a scene around `body`, load it, and
// check the error.
#include <gtest/gtest.h>
#include <string>
#include "core/error.h"
#include "scene/loaders.h"
#include "support/run.h"

namespace candela::test {

// Loading `<scene>body</scene>` from dir/scene.xml fails with one line that contains `needle` and
// `where` (the file, or the file and line: "scene.xml:2:").
inline void expect_load_error(const std::string& dir, const std::string& body, const std::string& needle,
                              const std::string& where = "scene.xml:") {
    const std::string path = dir + "/scene.xml";
    write_text(path, "<scene version=\"3.0.0\">\n" + body + "\n</scene>\n");
    try {
        load_scene(path);
        ADD_FAILURE() << "no error for " << body;
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(needle), std::string::npos) << what;
        EXPECT_NE(what.find(where), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
}

}  // namespace candela::test
