#include "scene_input.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <iterator>

#include "compiler.h"

namespace pcsg::tools {

CompiledScene compileScene(const std::string& path, std::ostream& err) {
    CompiledScene result;
    std::string storage;  // the source text: outlives diags, whose messages quote it
    Diagnostics diags;
    const auto start = std::chrono::steady_clock::now();
    if (path == "-") {
        storage.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
        result.graph = compileSource("<stdin>", storage, diags);
    } else if (std::error_code ec; std::filesystem::is_directory(path, ec)) {
        err << path << ": error: this is a directory, not a scene file\n";
        return result;
    } else {
        result.graph = compileFile(path, storage, diags);
    }
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (diags.hasErrors()) err << diags.format() << std::flush;
    if (diags.hasErrors()) result.graph.reset();
    return result;
}

}  // namespace pcsg::tools
