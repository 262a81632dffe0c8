// Verifying one scene: render it natively (the cyclic graph) and with POV-Ray (the
// expanded tree written by export-pov), both without anti-aliasing at K times the size,
// reduce both by the same K×K box filter and compare them (pcsg-image compare). Shared by
// `pcsg verify` (verify_command.cpp) and `pcsg fuzz` (fuzz_command.cpp), so that both
// judge a scene by the same renders and the same thresholds.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "verify_result.h"

namespace CLI {
class App;
}

namespace pcsg::tools {

struct SceneVerifyOptions : VerifySettings {
    std::string povFile;      // render this POV-Ray file instead of the export (gets +K)
    std::string imageHelper;  // pcsg-image
    double clock = 0;         // --clock: both sides render the still at this time
    int frame = 1;            // a frame of --frames: its number, passed on with its clock
    // The arguments that pass --clock (and --frame) on to render, export-pov and stats
    // (none for a still at clock 0).
    std::vector<std::string> clockArgs() const;
};

// The options `pcsg verify` and `pcsg fuzz` share, with verify's defaults: --width,
// --height, --ss and --threads; and the thresholds --pixel-threshold, --max-off and
// --max-mean-error.
void addImageOptions(CLI::App* cmd, SceneVerifyOptions& o);
void addThresholdOptions(CLI::App* cmd, SceneVerifyOptions& o);

// The scene's text for the report (up to 256 KB); empty when it cannot be read.
std::string readSource(const std::string& scene);

// Verifies one scene (at o.clock), writing its images into root/dir: native.png,
// povray.png (both reduced) and diff.png (the heat map), and the exported DIR.pov.
// status 0: the images agree, 1: they differ (or POV-Ray rejected the export), 2: a
// render could not run (the message says why).
SceneResult verifyScene(const std::string& scene, const std::string& dir,
                        const SceneVerifyOptions& o, const std::filesystem::path& root);

}  // namespace pcsg::tools
