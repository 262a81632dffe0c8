// The animation row of pcsg bench: see bench_animation.h.
#include "bench_animation.h"

#include <fmt/format.h>

#include <system_error>
#include <vector>

#include "child_process.h"
#include "renders.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> threadArgs(const AnimationBenchOptions& o, const char* flag) {
    if (o.threads <= 0) return {};
    if (std::string(flag) == "+WT") return {"+WT" + std::to_string(o.threads)};
    return {flag, std::to_string(o.threads)};
}

// `pcsg render SCENE -o DIR/anim.png --frames N`: every frame in one command.
void nativeSide(const AnimationBenchOptions& o, const fs::path& dir, AnimationRow& row) {
    std::vector<std::string> argv = {selfExecutable(),
                                     "render",
                                     o.scene,
                                     "-o",
                                     (dir / "anim.png").string(),
                                     "--frames",
                                     std::to_string(o.frames),
                                     "--width",
                                     std::to_string(o.width),
                                     "--height",
                                     std::to_string(o.height),
                                     "--adaptive",
                                     fmt::format("{}", o.adaptive)};
    for (const std::string& a : threadArgs(o, "--threads")) argv.push_back(a);
    const ChildResult c = runChild(argv);
    row.nativeOk = c.started && c.exitCode == 0;
    if (!row.nativeOk) row.note = "native render failed:\n" + firstLines(c.err);
    row.nativeSeconds = c.seconds;
    row.nativeRss = c.peakRssBytes;
}

// `pcsg export-pov --frames N`, then `povray anim.ini` in the frames' directory.
void povraySide(const AnimationBenchOptions& o, const fs::path& dir, AnimationRow& row) {
    const RenderRun exported = exportPov(o.scene, (dir / "anim.pov").string(), o.width, o.height,
                                         {"--frames", std::to_string(o.frames)});
    if (!exported.ok) {
        row.note = "not exported: " + exported.error;
        return;
    }
    row.exportSeconds = exported.child.seconds;
    std::string povray = fmt::format("cd '{}' && exec povray anim.ini -D -V -P {}", dir.string(),
                                     o.adaptive > 0 ? fmt::format("+A{}", o.adaptive) : "-A");
    for (const std::string& a : threadArgs(o, "+WT")) povray += " " + a;
    const ChildResult c = runChild({"sh", "-c", povray});
    row.povOk =
        c.started && c.exitCode == 0 &&
        fs::exists(dir / fmt::format("anim{:0{}}.png", o.frames, std::to_string(o.frames).size()));
    if (!row.povOk) row.note = "POV-Ray could not render the frames:\n" + firstLines(c.err);
    row.povraySeconds = c.seconds;
    row.povRss = c.peakRssBytes;
}

}  // namespace

AnimationRow benchAnimation(const AnimationBenchOptions& o, const fs::path& work) {
    AnimationRow row;
    row.scene = fs::path(o.scene).stem().string();
    row.frames = o.frames;
    const fs::path native = work / "animation_native", pov = work / "animation_povray";
    fs::create_directories(native);
    fs::create_directories(pov);
    nativeSide(o, native, row);
    if (row.nativeOk && !o.nativeOnly) povraySide(o, pov, row);
    std::error_code ec;
    fs::remove_all(native, ec);
    fs::remove_all(pov, ec);
    return row;
}

AnimationRow medianAnimation(const std::vector<AnimationRow>& repetitions) {
    for (const AnimationRow& r : repetitions)
        if (!r.nativeOk) return r;
    const auto of = [&repetitions](auto AnimationRow::*field) {
        return medianOf(repetitions, [field](const AnimationRow& r) { return r.*field; });
    };
    AnimationRow out = repetitions.front();
    out.nativeSeconds = of(&AnimationRow::nativeSeconds);
    out.nativeRss = static_cast<uint64_t>(of(&AnimationRow::nativeRss));
    for (const AnimationRow& r : repetitions)
        if (!r.povOk) {
            out.povOk = false;
            out.note = r.note;
            break;
        }
    if (out.povOk) {
        out.exportSeconds = of(&AnimationRow::exportSeconds);
        out.povraySeconds = of(&AnimationRow::povraySeconds);
        out.povRss = static_cast<uint64_t>(of(&AnimationRow::povRss));
    }
    out.runs.clear();
    for (const AnimationRow& r : repetitions)
        out.runs.push_back({r.nativeSeconds, r.povSeconds(), r.nativeRss, r.povRss, r.povOk});
    return out;
}

}  // namespace pcsg::tools
