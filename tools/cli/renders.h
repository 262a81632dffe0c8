// Running the two renderers as measured child processes: the native tracer (`pcsg
// render`, this executable) and POV-Ray on exported text. Shared by verify and bench.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "child_process.h"

namespace pcsg::tools {

struct RenderRun {
    ChildResult child;
    bool ok = false;
    std::string error;                   // why it failed, with the start of its stderr
    std::optional<nlohmann::json> json;  // what `pcsg ... --json` printed
    std::optional<double> parseSeconds;  // POV-Ray's own parse time
    std::optional<double> traceSeconds;  // POV-Ray's own trace time
};

// `pcsg render SCENE -o OUT --width W --height H --json [extra...]`.
RenderRun renderNative(const std::string& scene, const std::string& out, int width, int height,
                       const std::vector<std::string>& extra = {});

// `pcsg export-pov SCENE -o OUT --width W --height H [extra...]`.
RenderRun exportPov(const std::string& scene, const std::string& out, int width, int height,
                    const std::vector<std::string>& extra = {});

// `pcsg stats SCENE --json` (and `extra`, e.g. --clock).
RenderRun expandedStats(const std::string& scene, const std::vector<std::string>& extra = {});

// `povray +I... +O... +W +H -D +FN -UA -P -V [extra...]` (extra: "-A", "+A0.3", "+WT2").
// `started` false in the result when POV-Ray is not installed.
RenderRun renderPovray(const std::string& pov, const std::string& out, int width, int height,
                       const std::vector<std::string>& extra);

// Reads an optional number from a JSON object.
template <class T>
std::optional<T> jsonField(const std::optional<nlohmann::json>& j, const char* key) {
    if (j && j->is_object() && j->contains(key) && (*j)[key].is_number()) return (*j)[key].get<T>();
    return std::nullopt;
}

// The first lines of a text, indented, for error messages.
std::string firstLines(const std::string& text, size_t n = 12);

inline const char* kPovrayInstallHint =
    "POV-Ray is not installed: install it with `apt-get install povray`";

}  // namespace pcsg::tools
