// pcsg bench --repeat: the medians of repeated rows, and the range of their ratios.
#include "bench_median.h"

#include <gtest/gtest.h>

#include "bench_animation.h"

namespace pcsg::tools {
namespace {

BenchRow rowOf(double native, double pov, uint64_t nativeRss, uint64_t povRss) {
    BenchRow r;
    r.scene = "terrain";
    r.nativeOk = r.povOk = true;
    r.nativeSeconds = r.nativeCommandSeconds = native;
    r.povSeconds = pov;
    r.nativeRss = nativeRss;
    r.povRss = povRss;
    r.raysPerSecond = 1000 / native;
    r.povParseSeconds = pov / 2;
    r.primitives = 2097152;
    return r;
}

TEST(BenchMedian, MedianOfOddAndEvenCounts) {
    EXPECT_EQ(median({}), 0);
    EXPECT_EQ(median({3}), 3);
    EXPECT_EQ(median({5, 1, 3}), 3);
    EXPECT_EQ(median({4, 1, 3, 2}), 2.5);
}

TEST(BenchMedian, EachFigureIsTheMedianOfItsOwnAndTheRunsAreKept) {
    // The slow native run is the second; POV-Ray's slowest is the third: a ratio of medians,
    // not the ratio of one run.
    const BenchRow m =
        medianRow({rowOf(1.0, 20, 40, 900), rowOf(2.0, 18, 44, 920), rowOf(1.5, 25, 42, 910)});
    EXPECT_TRUE(m.nativeOk);
    EXPECT_TRUE(m.povOk);
    EXPECT_EQ(m.scene, "terrain");
    EXPECT_EQ(m.nativeSeconds, 1.5);
    EXPECT_EQ(m.nativeCommandSeconds, 1.5);
    EXPECT_EQ(m.povSeconds, 20);
    EXPECT_EQ(m.nativeRss, 42u);
    EXPECT_EQ(m.povRss, 910u);
    EXPECT_EQ(*m.povParseSeconds, 10);
    EXPECT_DOUBLE_EQ(*m.raysPerSecond, 1000 / 1.5);
    EXPECT_EQ(*m.primitives, 2097152u);
    ASSERT_EQ(m.runs.size(), 3u);
    EXPECT_EQ(m.runs[1].nativeSeconds, 2.0);
    EXPECT_EQ(m.runs[2].povSeconds, 25);
    const std::vector<double> ratios = timeRatios(m.runs);
    ASSERT_EQ(ratios.size(), 3u);
    EXPECT_EQ(ratios[0], 20);
    EXPECT_EQ(ratios[1], 9);
    EXPECT_EQ(runsText(ratios), "; runs 9.00-20.00");
    EXPECT_EQ(runsText(rssRatios(m.runs), 1), "; runs 20.9-22.5");
}

TEST(BenchMedian, AFailedNativeRunIsTheRow) {
    BenchRow failed = rowOf(1.0, 20, 40, 900);
    failed.nativeOk = false;
    failed.note = "native render failed";
    const BenchRow m = medianRow({rowOf(1.0, 20, 40, 900), failed});
    EXPECT_FALSE(m.nativeOk);
    EXPECT_EQ(m.note, "native render failed");
}

TEST(BenchMedian, PovrayAndEmbreeOnlyWhereEveryRunHasThem) {
    BenchRow a = rowOf(1.0, 20, 40, 900), b = rowOf(3.0, 20, 40, 900);
    a.embree = EmbreeRun{100, 0.5, 0.1, 10, 1, 400};
    b.povOk = false;
    b.note = "POV-Ray could not render";
    const BenchRow m = medianRow({a, b});
    EXPECT_TRUE(m.nativeOk);
    EXPECT_EQ(m.nativeSeconds, 2.0);
    EXPECT_FALSE(m.povOk);
    EXPECT_EQ(m.note, "POV-Ray could not render");
    EXPECT_FALSE(m.embree.has_value());
    EXPECT_EQ(timeRatios(m.runs).size(), 1u) << "only the run where both rendered";
    EXPECT_EQ(runsText(timeRatios(m.runs)), "") << "one ratio: no range";

    b = rowOf(3.0, 20, 40, 900);
    b.embree = EmbreeRun{100, 1.5, 0.3, 30, 3, 600};
    const BenchRow both = medianRow({a, b});
    ASSERT_TRUE(both.embree.has_value());
    EXPECT_EQ(both.embree->buildSeconds, 1.0);
    EXPECT_DOUBLE_EQ(both.embree->traceSeconds, 0.2);
    EXPECT_EQ(both.embree->raysPerSecond, 20);
    EXPECT_EQ(both.embree->peakRss, 500u);
}

TEST(BenchMedian, TheNativeTraceOnlyWhereEveryRunHasIt) {
    BenchRow a = rowOf(1.0, 20, 40, 900), b = rowOf(3.0, 20, 40, 900), c = rowOf(2.0, 20, 40, 900);
    a.nativeTrace = NativeTraceRun{0.4, 0.1, 9e6, 900, 0};
    b.nativeTrace = NativeTraceRun{0.8, 0.3, 3e6, 900, 5};
    EXPECT_FALSE(medianRow({a, b, c}).nativeTrace.has_value()) << "c has none";
    c.nativeTrace = NativeTraceRun{0.6, 0.2, 4e6, 900, 2};
    const BenchRow m = medianRow({a, b, c});
    ASSERT_TRUE(m.nativeTrace.has_value());
    EXPECT_DOUBLE_EQ(m.nativeTrace->buildSeconds, 0.6);
    EXPECT_DOUBLE_EQ(m.nativeTrace->traceSeconds, 0.2);
    EXPECT_DOUBLE_EQ(m.nativeTrace->raysPerSecond, 4e6) << "the median, not the first";
    EXPECT_EQ(m.nativeTrace->rays, 900u);
}

TEST(BenchMedian, AnimationRowsTakeTheMedianOfBothSides) {
    auto row = [](double native, double pov, uint64_t rss) {
        AnimationRow a;
        a.scene = "growing_tree";
        a.frames = 48;
        a.nativeOk = a.povOk = true;
        a.nativeSeconds = native;
        a.exportSeconds = 0.5;
        a.povraySeconds = pov;
        a.nativeRss = rss;
        a.povRss = 60;
        return a;
    };
    const AnimationRow m = medianAnimation({row(5, 18, 6), row(4, 19, 5), row(6, 17, 7)});
    EXPECT_EQ(m.nativeSeconds, 5);
    EXPECT_EQ(m.povraySeconds, 18);
    EXPECT_EQ(m.nativeRss, 6u);
    ASSERT_EQ(m.runs.size(), 3u);
    EXPECT_EQ(m.runs[1].povSeconds, 19.5) << "the export counts on POV-Ray's side";
    EXPECT_EQ(runsText(rssRatios(m.runs), 1), "; runs 8.6-12.0");

    AnimationRow noPov = row(4, 0, 5);
    noPov.povOk = false;
    noPov.note = "POV-Ray could not render the frames";
    const AnimationRow n = medianAnimation({row(5, 18, 6), noPov, row(6, 17, 7)});
    EXPECT_EQ(n.nativeSeconds, 5);
    EXPECT_FALSE(n.povOk);
    EXPECT_EQ(n.note, "POV-Ray could not render the frames");
}

}  // namespace
}  // namespace pcsg::tools
