#include "bench_median.h"

#include <fmt/format.h>

#include <algorithm>

namespace pcsg::tools {

double SideBySideRun::timeRatio() const {
    return povSeconds / std::max(nativeSeconds, 1e-9);
}

double SideBySideRun::rssRatio() const {
    return double(povRss) / double(std::max<uint64_t>(nativeRss, 1));
}

double median(std::vector<double> values) {
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    const size_t m = values.size() / 2;
    return values.size() % 2 ? values[m] : (values[m - 1] + values[m]) / 2;
}

namespace {

uint64_t medianBytes(const std::vector<BenchRow>& rows, uint64_t BenchRow::*field) {
    return static_cast<uint64_t>(medianOf(rows, [field](const BenchRow& r) { return r.*field; }));
}

// Embree's figures, the median of each, when every repetition traced the scene.
std::optional<EmbreeRun> medianEmbree(const std::vector<BenchRow>& rows) {
    for (const BenchRow& r : rows)
        if (!r.embree) return std::nullopt;
    EmbreeRun e = *rows.front().embree;
    const auto of = [&rows](double EmbreeRun::*field) {
        return medianOf(rows, [field](const BenchRow& r) { return (*r.embree).*field; });
    };
    e.buildSeconds = of(&EmbreeRun::buildSeconds);
    e.traceSeconds = of(&EmbreeRun::traceSeconds);
    e.raysPerSecond = of(&EmbreeRun::raysPerSecond);
    e.seconds = of(&EmbreeRun::seconds);
    e.peakRss =
        static_cast<uint64_t>(medianOf(rows, [](const BenchRow& r) { return r.embree->peakRss; }));
    return e;
}

// pcsg-trace's figures, the median of each, when every repetition traced the scene.
std::optional<NativeTraceRun> medianNativeTrace(const std::vector<BenchRow>& rows) {
    for (const BenchRow& r : rows)
        if (!r.nativeTrace) return std::nullopt;
    NativeTraceRun n = *rows.front().nativeTrace;
    const auto of = [&rows](double NativeTraceRun::*field) {
        return medianOf(rows, [field](const BenchRow& r) { return (*r.nativeTrace).*field; });
    };
    n.buildSeconds = of(&NativeTraceRun::buildSeconds);
    n.traceSeconds = of(&NativeTraceRun::traceSeconds);
    n.raysPerSecond = of(&NativeTraceRun::raysPerSecond);
    return n;
}

// POV-Ray's figures, the median of each, when every repetition rendered it.
void medianPovray(const std::vector<BenchRow>& rows, BenchRow& out) {
    for (const BenchRow& r : rows)
        if (!r.povOk) {
            out.povOk = false;
            out.note = r.note;
            return;
        }
    out.povOk = true;
    out.povSeconds = medianOf(rows, [](const BenchRow& r) { return r.povSeconds; });
    out.povRss = medianBytes(rows, &BenchRow::povRss);
    if (std::all_of(rows.begin(), rows.end(),
                    [](const BenchRow& r) { return r.povParseSeconds.has_value(); }))
        out.povParseSeconds = medianOf(rows, [](const BenchRow& r) { return *r.povParseSeconds; });
}

}  // namespace

BenchRow medianRow(const std::vector<BenchRow>& repetitions) {
    for (const BenchRow& r : repetitions)
        if (!r.nativeOk) return r;
    BenchRow out = repetitions.front();
    out.nativeSeconds = medianOf(repetitions, [](const BenchRow& r) { return r.nativeSeconds; });
    out.nativeRss = medianBytes(repetitions, &BenchRow::nativeRss);
    out.nativeCommandSeconds =
        medianOf(repetitions, [](const BenchRow& r) { return r.nativeCommandSeconds; });
    if (out.raysPerSecond)
        out.raysPerSecond =
            medianOf(repetitions, [](const BenchRow& r) { return r.raysPerSecond.value_or(0); });
    medianPovray(repetitions, out);
    out.embree = medianEmbree(repetitions);
    out.nativeTrace = medianNativeTrace(repetitions);
    out.runs.clear();
    for (const BenchRow& r : repetitions)
        out.runs.push_back({r.nativeSeconds, r.povSeconds, r.nativeRss, r.povRss, r.povOk});
    return out;
}

std::string runsText(const std::vector<double>& ratios, int decimals) {
    if (ratios.size() < 2) return "";
    const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
    return fmt::format("; runs {:.{}f}-{:.{}f}", *lo, decimals, *hi, decimals);
}

std::vector<double> timeRatios(const std::vector<SideBySideRun>& runs) {
    std::vector<double> v;
    for (const SideBySideRun& r : runs)
        if (r.povOk) v.push_back(r.timeRatio());
    return v;
}

std::vector<double> rssRatios(const std::vector<SideBySideRun>& runs) {
    std::vector<double> v;
    for (const SideBySideRun& r : runs)
        if (r.povOk) v.push_back(r.rssRatio());
    return v;
}

}  // namespace pcsg::tools
