// pcsg graph FILE [-o OUT]: the scene's cyclic CSG graph as Graphviz DOT (graph_dot.h),
// on standard output, into OUT.dot/OUT.gv, or drawn by Graphviz's `dot` into
// OUT.svg/OUT.png/OUT.pdf.
#include <fmt/format.h>
#include <stdlib.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "child_process.h"
#include "commands.h"
#include "graph_dot.h"
#include "scene_input.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

struct GraphOptions {
    std::string scene;
    std::string output;  // empty: DOT to standard output
};

// The output's extension, lower case, without the dot.
std::string extensionOf(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    if (!ext.empty()) ext.erase(0, 1);
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

bool isDotFile(const std::string& ext) {
    return ext == "dot" || ext == "gv";
}
bool isDrawing(const std::string& ext) {
    return ext == "svg" || ext == "png" || ext == "pdf";
}

// Writes `text` to `path`; false with a message on `std::cerr` when it cannot.
bool writeFile(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    if (out) out << text;
    if (out) out.flush();
    if (!out) {
        std::cerr << fmt::format("pcsg graph: error: cannot write '{}': {}\n", path,
                                 std::strerror(errno));
        return false;
    }
    return true;
}

// Draws the DOT text with Graphviz into `path` (svg, png or pdf by its extension).
int drawWithGraphviz(const std::string& dot, const std::string& path, const std::string& ext) {
    if (!inPath("dot")) {
        std::cerr << fmt::format(
            "pcsg graph: error: writing {} needs Graphviz's `dot` program, which is not "
            "installed\n  install it with `apt-get install graphviz`, or write DOT text "
            "with `-o {}.dot`\n",
            ext, fs::path(path).stem().string());
        return 2;
    }
    char tmpl[] = "/tmp/pcsg-graph-XXXXXX";
    if (!mkdtemp(tmpl)) {
        std::cerr << fmt::format("pcsg graph: error: cannot make a temporary directory: {}\n",
                                 std::strerror(errno));
        return 2;
    }
    const fs::path dir = tmpl;
    const std::string dotPath = (dir / "graph.dot").string();
    int status = 0;
    if (!writeFile(dotPath, dot)) {
        status = 2;
    } else {
        const ChildResult r = runChild({"dot", "-T" + ext, dotPath, "-o", path});
        if (!r.started || r.exitCode != 0) {
            std::cerr << fmt::format("pcsg graph: error: `dot -T{}` failed (exit status {})\n{}",
                                     ext, r.exitCode, r.err);
            std::error_code ec;
            fs::remove(path, ec);  // no partial picture in place of the requested one
            status = 2;
        } else if (!r.err.empty()) {
            std::cerr << r.err;  // Graphviz's warnings, if any
        }
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    return status;
}

int runGraph(const GraphOptions& o) {
    const CompiledScene compiled = compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    DotOptions options;
    options.title = o.scene == "-" ? std::string("<stdin>") : fs::path(o.scene).filename().string();
    const std::string dot = toDot(*compiled.graph, options);
    if (o.output.empty()) {
        std::cout << dot << std::flush;
        return std::cout ? 0 : 2;
    }
    const std::string ext = extensionOf(o.output);
    if (isDotFile(ext)) return writeFile(o.output, dot) ? 0 : 2;
    return drawWithGraphviz(dot, o.output, ext);
}

}  // namespace

void addGraphCommand(CLI::App& app, int& status) {
    auto o = std::make_shared<GraphOptions>();
    auto* cmd = app.add_subcommand(
        "graph",
        "Write a scene's cyclic CSG graph as Graphviz DOT (S-nodes are the targets of the "
        "dashed back edges), or draw it as SVG, PNG or PDF with Graphviz's dot");
    cmd->add_option("scene", o->scene, "The .pcsg file (- reads standard input)")->required();
    cmd->add_option("-o,--output", o->output,
                    "Output file: .dot or .gv for DOT text, .svg, .png or .pdf for a picture "
                    "(needs Graphviz); DOT goes to standard output without -o")
        ->check(CLI::Validator(
            [](std::string& path) -> std::string {
                const std::string ext = extensionOf(path);
                if (isDotFile(ext) || isDrawing(ext)) return "";
                return "the output must end in .dot, .gv, .svg, .png or .pdf: " + path;
            },
            "FILE.dot|.gv|.svg|.png|.pdf"));
    cmd->callback([o, &status] { status = runGraph(*o); });
}

}  // namespace pcsg::tools
