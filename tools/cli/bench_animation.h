// The animation row of `pcsg bench`: N frames of an animated scene rendered natively by
// one `pcsg render --frames N` command, against POV-Ray rendering the N exported frames by
// one `povray OUT.ini` command (the export's driver: POV-Ray's own way to render a
// sequence). Both are whole commands as /usr/bin/time -v counts them: wall time and peak
// RSS. The export's own time is counted on POV-Ray's side, since POV-Ray needs it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_median.h"

namespace pcsg::tools {

struct AnimationBenchOptions {
    std::string scene;  // an animated scene (growing_tree by default)
    int frames = 48;
    int width = 640, height = 480;
    double adaptive = 0.3;
    int threads = 0;
    bool nativeOnly = false;
};

struct AnimationRow {
    std::string scene;
    int frames = 0;
    bool nativeOk = false, povOk = false;
    std::string note;          // why a side failed
    double nativeSeconds = 0;  // the whole `pcsg render --frames` command
    uint64_t nativeRss = 0;    // its peak RSS
    double exportSeconds = 0;  // `pcsg export-pov --frames`
    double povraySeconds = 0;  // the whole `povray OUT.ini` command
    uint64_t povRss = 0;       // its peak RSS
    double povSeconds() const { return exportSeconds + povraySeconds; }
    std::vector<SideBySideRun> runs;  // each repetition (medianAnimation: more than one)
};

// Renders both ways in `work` (removing the frames afterwards).
AnimationRow benchAnimation(const AnimationBenchOptions& o, const std::filesystem::path& work);

// The row of N repetitions (bench_median.h): the first failed one as it is, else each
// figure the median of the repetitions', and `runs` each repetition's.
AnimationRow medianAnimation(const std::vector<AnimationRow>& repetitions);

}  // namespace pcsg::tools
