#pragma once
#include <stdexcept>
#include <string>

namespace candela {

// Every user-facing failure (bad file, bad parameter, impossible request) is thrown as an Error
// whose message is one line that names the file and, where known, the line: "file:line: what".
// The program prints it and exits non-zero; nothing below the app layer prints or exits itself.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& what) : std::runtime_error(what) {}
    Error(const std::string& file, int line, const std::string& what)
        : std::runtime_error(line > 0 ? file + ":" + std::to_string(line) + ": " + what : file + ": " + what) {}
};

}  // namespace candela
