#pragma once
// One <bsdf> loaded through candela's XML reader, as the BSDF tests against Mitsuba need it: a scene
// holding a rectangle with that BSDF, written to a temp dir named after the test file.
#include <gtest/gtest.h>
#include <fstream>
#include <string>
#include "core/error.h"
#include "scene/loaders.h"
#include "support/run.h"

namespace candela::test {

inline std::string write_bsdf_scene(const std::string& dir, const std::string& name, const std::string& bsdf_xml) {
    const std::string path = temp_dir(dir) + "/" + name + ".xml";
    std::ofstream(path) << "<scene version=\"3.0.0\">\n<shape type=\"rectangle\">" << bsdf_xml << "</shape>\n</scene>\n";
    return path;
}

inline Material load_bsdf_material(const std::string& dir, const std::string& name, const std::string& bsdf_xml) {
    SceneDescription s = load_mitsuba_xml(write_bsdf_scene(dir, name, bsdf_xml), {});
    return s.materials[s.shapes.at(0).material];
}

// The loader's message for a bad <bsdf>, checked to be one line naming the file and line.
inline std::string load_bsdf_error(const std::string& dir, const std::string& name, const std::string& bsdf_xml) {
    const std::string path = write_bsdf_scene(dir, name, bsdf_xml);
    try {
        load_mitsuba_xml(path, {});
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(path + ":"), std::string::npos) << msg;  // file:line
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;        // one line
        return msg;
    }
    return "<no error>";
}

}  // namespace candela::test
