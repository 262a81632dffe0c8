// Helpers for tests that run the built `pcsg` executable (PCSG_EXECUTABLE) on small
// scene files written into a temporary directory, and the `pcsg-image` helper
// (PCSG_IMAGE_EXECUTABLE).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "child_process.h"

namespace pcsg::tools::testing {

// The paper's figure 3a (with the parentheses docs/language.md asks for) and figure 2.
inline const char* kSierpinskiA = R"(// figure 3a
{c=6} S
S if(c > 0, 2, 1)
1: S -> tetrahedron
2: S -> {c=c-1} ( move(0.5,0.5,0.5) uscale(0.5) S ∪
                  move(-0.5,-0.5,0.5) uscale(0.5) S ∪
                  move(0.5,-0.5,-0.5) uscale(0.5) S ∪
                  move(-0.5,0.5,-0.5) uscale(0.5) S )
)";

inline const char* kSierpinskiB = R"(// figure 2
w:  S(6)
p1: S(c) : c = 0 -> tetrahedron
p2: S(c) : c > 0 -> move(0.5,0.5,0.5) uscale(0.5) S(c-1) ∪
                    move(-0.5,-0.5,0.5) uscale(0.5) S(c-1) ∪
                    move(0.5,-0.5,-0.5) uscale(0.5) S(c-1) ∪
                    move(-0.5,0.5,-0.5) uscale(0.5) S(c-1)
)";

// A temporary directory, removed with everything in it at the end of the test.
class TempDir {
  public:
    TempDir() {
        std::string tmpl =
            (std::filesystem::temp_directory_path() / "pcsg-cli-test-XXXXXX").string();
        path_ = mkdtemp(tmpl.data()) ? tmpl : std::string();
    }
    ~TempDir() {
        std::error_code ec;
        if (!path_.empty()) std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    std::string file(const std::string& name) const { return path_ + "/" + name; }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(file(name), std::ios::binary) << text;
        return file(name);
    }
    const std::string& path() const { return path_; }

  private:
    std::string path_;
};

inline std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Runs `pcsg args...`.
inline ChildResult pcsg(std::vector<std::string> args) {
    args.insert(args.begin(), PCSG_EXECUTABLE);
    return runChild(args);
}

// Runs `pcsg-image args...` with `input` on its standard input.
inline ChildResult pcsgImage(std::vector<std::string> args, std::span<const std::byte> input) {
    args.insert(args.begin(), PCSG_IMAGE_EXECUTABLE);
    return runChild(args, input);
}

// The names of the files in a directory, sorted (to see that nothing was left behind).
inline std::vector<std::string> filesIn(const std::string& dir) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec))
        names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace pcsg::tools::testing
