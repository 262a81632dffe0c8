// The HTML report of `pcsg verify --report`: one page per scene and an index of all.
//
// Static pages, with no scripts but the images' inline load handlers and nothing from
// elsewhere, linked by relative paths only, so the report directory can be moved or
// copied as a whole:
//
//   DIR/index.html                  every scene: its verdict, thumbnails and main figures
//   DIR/NAME/index.html             one scene: the three images, the metrics, memory, time
//   DIR/NAME/native.png, povray.png, diff.png, NAME.pov
//
// Every <img> marks itself from inline onload/onerror handlers: data-state="loaded" and
// data-natural="WxH", or data-state="broken", which also draws a red frame around it.
// tests/report_in_chromium.sh reads these marks from headless Chromium's DOM.
#pragma once

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "verify_result.h"

namespace pcsg::tools {

// A directory name for a scene inside the report: its file's stem, with anything but
// letters, digits, '.', '-' and '_' replaced, so that links need no escaping; a name
// already taken (two scenes/x.pcsg from different directories) gets "_2", "_3", ...
std::string reportDirName(const std::string& scene, std::set<std::string>& taken);

// Now, as the pages' footers say when they were written.
std::string localTime();

// DIR/NAME/index.html for one scene (r.dir is NAME).
void writeScenePage(const SceneResult& r, const VerifySettings& o, const std::string& written,
                    const std::filesystem::path& root);

// The index of all scenes, rewritten after each one so that a long run can be watched;
// `pending` scenes are still to come.
void writeIndex(const std::vector<SceneResult>& results, size_t pending, const VerifySettings& o,
                const std::string& written, const std::filesystem::path& root);

}  // namespace pcsg::tools
