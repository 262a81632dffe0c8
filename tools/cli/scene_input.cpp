#include "scene_input.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <iterator>

#include "compiler.h"
#include "eval.h"
#include "scene_time.h"

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

bool setSceneTime(Graph& g, Time t, std::ostream& err) {
    try {
        setTime(g, t);
        return true;
    } catch (const RuntimeError& e) {
        err << e.format(g) << "\n";
        return false;
    }
}

CLI::Option* addFrameOption(CLI::App* cmd, int& frame) {
    return cmd
        ->add_option("--frame", frame,
                     "The frame number of the still: `frame` reads it (default 1); with "
                     "--clock, frame F of a sequence rendered alone")
        ->check(CLI::Range(1, 1000000));
}

CLI::Option* addClockOption(CLI::App* cmd, double& clock) {
    const CLI::Validator finite(
        [](const std::string& s) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(s.c_str(), &end);
            if (s.empty() || *end != '\0' || !std::isfinite(v))
                return "a finite number is needed, found '" + s + "'";
            return {};
        },
        "FINITE");
    return cmd
        ->add_option("--clock", clock,
                     "The time of the still (docs/language.md section 11): `clock` reads this "
                     "value and `frame` reads 1 (default: clock 0)")
        ->check(finite);
}

}  // namespace pcsg::tools
