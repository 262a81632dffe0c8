// Compile-time diagnostics, printed like a C compiler's (docs/language.md section 8):
//
//   scene.pcsg:3:14: error: unknown function 'sine'
//     S if(sine(c) > 0, 2, 1)
//          ^
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "graph.h"

namespace pcsg {

// The byte offset at which each line of `text` starts (the first line's, 0, included).
std::vector<uint32_t> lineStartsOf(std::string_view text);

struct Diagnostic {
    FileLoc loc;
    std::string message;
};

class Diagnostics {
  public:
    // Registers a source text under a name; returns the file index for FileLoc::file.
    uint32_t addFile(std::string name, std::string_view text);

    void error(FileLoc loc, std::string message);
    bool hasErrors() const { return !errors_.empty(); }
    const std::vector<Diagnostic>& errors() const { return errors_; }
    // How many errors were reported, counting those past kMaxErrors that are not kept:
    // "did this step report an error" compares count()s, which errors().size() cannot
    // answer once the list is full.
    size_t count() const { return reported_; }

    // All diagnostics, each as "file:line:col: error: message", the source line and a
    // caret under the column (a line longer than 200 bytes is shown around the column).
    std::string format() const;
    const std::vector<std::string>& fileNames() const { return names_; }

    // Stops collecting after this many errors (the last one says so).
    static constexpr size_t kMaxErrors = 50;

  private:
    std::vector<std::string> names_;
    std::vector<std::string_view> texts_;
    std::vector<Diagnostic> errors_;
    size_t reported_ = 0;
};

}  // namespace pcsg
