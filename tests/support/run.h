#pragma once
// Runs the candela program from tests, capturing its output and exit code.
#include <sys/wait.h>
#include <unistd.h>
#include <cstdio>
#include <fstream>
#include <string>

namespace candela::test {

struct RunResult {
    int exit_code = -1;
    std::string output;  // stdout and stderr together
};

// Runs `command` with /bin/sh, stdout and stderr together.
inline RunResult run_shell(const std::string& command) {
    RunResult r;
    FILE* p = popen((command + " 2>&1").c_str(), "r");
    if (!p) return r;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
    int status = pclose(p);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return r;
}

// `env` adds variables ("NAME=value ..."), after DISPLAY and WAYLAND_DISPLAY are removed.
inline RunResult run_candela(const std::string& args, const std::string& env = "") {
    return run_shell(std::string("env -u DISPLAY -u WAYLAND_DISPLAY ") + env + " " + CANDELA_BIN + " " + args);
}

// A fresh scratch directory for one test (removed by the caller if it wants to).
inline std::string temp_dir(const std::string& name) {
    std::string d = "/tmp/candela-test-" + std::to_string(getpid()) + "-" + name;
    std::string cmd = "rm -rf '" + d + "' && mkdir -p '" + d + "'";
    if (std::system(cmd.c_str()) != 0) return "/tmp";
    return d;
}

inline void write_text(const std::string& path, const std::string& text) {
    std::ofstream f(path, std::ios::binary);
    f << text;
}

inline std::string read_bytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

}  // namespace candela::test
