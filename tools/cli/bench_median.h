// Repeated bench measurements (`pcsg bench --repeat N`): a row measured N times, one
// side-by-side repetition after the other, reports the median of each figure over the
// repetitions, and keeps each repetition's times and peaks so that the spread of the
// ratios can be shown beside the verdicts.
//
// On a shared machine one run of a whole command can be 20% slower than the next; the
// POV-Ray / native ratio of one run then says as much about the machine as about the
// renderers. The median of a few repetitions, each measured side by side, does not move
// with one slow run, and the spread shows how far a single run could have landed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "embree_run.h"

namespace pcsg::tools {

// One repetition of a row: both whole commands (povOk false: POV-Ray did not run or failed).
struct SideBySideRun {
    double nativeSeconds = 0, povSeconds = 0;
    uint64_t nativeRss = 0, povRss = 0;
    bool povOk = false;
    double timeRatio() const;  // POV-Ray's time over the native time
    double rssRatio() const;   // POV-Ray's peak RSS over the native peak RSS
};

// A scene's row of the bench table.
struct BenchRow {
    std::string scene;
    bool nativeOk = false, povOk = false;
    std::string note;
    double nativeSeconds = 0, povSeconds = 0;
    std::optional<double> povParseSeconds;
    // Of the whole render commands, as /usr/bin/time -v counts them (wait4's rusage).
    uint64_t nativeRss = 0, povRss = 0;
    std::optional<double> raysPerSecond;
    std::optional<uint64_t> primitives;
    double nativeCommandSeconds = 0;  // the whole `pcsg render` command's wall time
    std::optional<EmbreeRun> embree;  // a triangle-only scene that pcsg-embree traced
    // The same rays through pcsg's tracer (pcsg-trace), where Embree traced the scene.
    std::optional<NativeTraceRun> nativeTrace;
    std::vector<SideBySideRun> runs;  // each repetition (medianRow: more than one)
};

// The median of the values (the mean of the middle two for an even count; 0 for none).
double median(std::vector<double> values);

// The median of one figure, figure(row), over rows of any kind (BenchRow, AnimationRow).
template <typename Row, typename F>
double medianOf(const std::vector<Row>& rows, F&& figure) {
    std::vector<double> v;
    for (const Row& r : rows) v.push_back(double(figure(r)));
    return median(std::move(v));
}

// The row of N repetitions of one scene: the first failed repetition as it is (its native
// render failed), else each figure the median of the repetitions', POV-Ray's only where every
// repetition rendered it (else the first failure's note), Embree's and pcsg-trace's only
// where every repetition traced it. `runs` gets each repetition's.
BenchRow medianRow(const std::vector<BenchRow>& repetitions);

// "" for fewer than two ratios, else "; runs 8.94-12.58": the range of the per-run ratios,
// for a verdict's text.
std::string runsText(const std::vector<double>& ratios, int decimals = 2);

// The per-run time ratios and RSS ratios of the runs where both sides rendered.
std::vector<double> timeRatios(const std::vector<SideBySideRun>& runs);
std::vector<double> rssRatios(const std::vector<SideBySideRun>& runs);

}  // namespace pcsg::tools
