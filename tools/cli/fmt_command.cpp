// pcsg fmt FILE [-i | --check]: print a scene in its canonical layout (compiler/formatter.h),
// on standard output or, with -i, in place (a temporary file beside it, then a rename); or,
// with --check, only say whether it is in that layout already.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <string_view>

#include "commands.h"
#include "formatter.h"

namespace pcsg::tools {

namespace {

struct FmtOptions {
    std::string scene;
    bool inPlace = false;
    bool check = false;
};

// The exit status of --check for a file that formatting would change.
constexpr int kNotFormatted = 3;

// The first line (1-based) where two texts differ.
size_t firstDifferentLine(std::string_view a, std::string_view b) {
    const auto at = std::mismatch(a.begin(), a.end(), b.begin(), b.end()).first;
    return static_cast<size_t>(std::count(a.begin(), at, '\n')) + 1;
}

// Replaces `path` by `text` atomically: a temporary file in the same directory, with the
// original's permissions, renamed over it.
bool writeAtomically(const std::string& path, const std::string& text) {
    std::string tmpl = path + ".fmt-XXXXXX";
    const int fd = mkstemp(tmpl.data());
    if (fd < 0) return false;
    size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n <= 0) break;
        done += static_cast<size_t>(n);
    }
    const bool ok = done == text.size() && ::fsync(fd) == 0;
    ::close(fd);
    std::error_code ec;
    if (ok) {
        const auto perms = std::filesystem::status(path, ec).permissions();
        if (!ec) std::filesystem::permissions(tmpl, perms, ec);
    }
    if (!ok || std::rename(tmpl.c_str(), path.c_str()) != 0) {
        std::filesystem::remove(tmpl, ec);
        return false;
    }
    return true;
}

int runFmt(const FmtOptions& o) {
    std::string text;
    if (o.scene == "-") {
        text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    } else {
        std::error_code ec;
        std::ifstream in(o.scene, std::ios::binary);
        if (std::filesystem::is_directory(o.scene, ec) || !in) {
            std::cerr << o.scene << ": error: cannot read the file\n";
            return 1;
        }
        text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    const std::string name = o.scene == "-" ? "<stdin>" : o.scene;
    Diagnostics diags;
    const std::optional<std::string> out = formatScene(name, text, diags);
    if (!out) {
        std::cerr << diags.format() << std::flush;
        return 1;
    }
    if (o.check) {
        if (*out == text) return 0;
        std::cerr << fmt::format("{}:{}: not in pcsg fmt's layout from this line on\n", name,
                                 firstDifferentLine(text, *out));
        return kNotFormatted;
    }
    if (!o.inPlace) {
        std::cout << *out << std::flush;
        return 0;
    }
    if (*out == text) return 0;
    if (!writeAtomically(o.scene, *out)) {
        std::cerr << fmt::format("{}: error: cannot write the file: {}\n", o.scene,
                                 std::strerror(errno));
        return 2;
    }
    return 0;
}

}  // namespace

void addFmtCommand(CLI::App& app, int& status) {
    auto o = std::make_shared<FmtOptions>();
    auto* cmd = app.add_subcommand(
        "fmt",
        "Print a scene in its canonical layout (as gofmt does): one statement per line, one "
        "spacing, `∪ ∩ \\` and `->`, numbers as written, lines over 100 columns broken after "
        "`∪` (or `∩`, `\\`), comments kept (in a C-node or directive beside their items, one a "
        "line; "
        "elsewhere inside a "
        "statement moved to the line before it). A scene that "
        "does not compile gets its errors and exit status 1, and nothing is written. Macros "
        "are kept: each #define as written, each use as the macro's name where its body is a "
        "whole C-node block, expression or CSG term (else the file is refused, with the "
        "place).");
    cmd->add_option("scene", o->scene, "The .pcsg file (- reads standard input, without -i)")
        ->required();
    cmd->add_flag("-i,--in-place", o->inPlace,
                  "Rewrite the file in place (atomically: a temporary file, then a rename)");
    cmd->add_flag("--check", o->check,
                  "Write nothing: exit status 0 when the scene is in its canonical layout "
                  "already, 3 when pcsg fmt would change it (the first line that would change "
                  "goes to standard error), 1 when it does not compile");
    cmd->callback([o, &status] {
        if (o->inPlace && o->scene == "-")
            throw CLI::ValidationError("-i", "cannot rewrite standard input in place");
        if (o->inPlace && o->check)
            throw CLI::ValidationError("--check", "writes nothing: it cannot go with -i");
        status = runFmt(*o);
    });
}

}  // namespace pcsg::tools
