// pcsg bench --plot: the SVG drawn from a sweep, and the command that measures one.
#include "bench_plot.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "child_process.h"
#include "cli_test_util.h"

namespace pcsg::tools {
namespace {

using testing::pcsg;
using testing::readFile;
using testing::TempDir;

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(ScalingSvg, ALineAndAMarkerPerRendererAndOrderItRan) {
    // pcsg at orders 4 to 7, POV-Ray stopping after 5, Embree never run.
    std::vector<ScalingPoint> points;
    for (int k = 4; k <= 7; ++k) {
        ScalingPoint p;
        p.order = k;
        p.seconds[kScalingNative] = 0.5 + 0.1 * k;
        p.rss[kScalingNative] = 17u << 20;
        if (k <= 5) {
            p.seconds[kScalingPovray] = 0.2 * (1 << (2 * (k - 4)));
            p.rss[kScalingPovray] = uint64_t(40) << (20 + 2 * (k - 4));
        }
        points.push_back(p);
    }
    const std::string svg = scalingSvg(points, "caption <&>");
    EXPECT_EQ(svg.rfind("<svg", 0), 0u);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    EXPECT_EQ(count(svg, "<path"), 4u) << "two series in two panels";
    EXPECT_EQ(count(svg, "<circle"), 2u * (4 + 2));
    EXPECT_EQ(count(svg, "stroke='#7570b3'"), 0u) << "no Embree line";
    EXPECT_NE(svg.find("caption &lt;&amp;&gt;"), std::string::npos);
    // The memory panel spans POV-Ray's 640 MB: a decade tick at 1 GB or above it.
    EXPECT_NE(svg.find("1.0 GB"), std::string::npos) << svg;
}

TEST(ScalingSvg, TheScenesGrowFourfoldPerOrder) {
    EXPECT_NE(sierpinskiScene(3).find("{c=3} S"), std::string::npos);
    TempDir dir;
    for (int k : {1, 3}) {
        const std::string scene = dir.write("s.pcsg", sierpinskiScene(k));
        const ChildResult r = pcsg({"stats", scene, "--json"});
        ASSERT_EQ(r.exitCode, 0) << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)["primitive_equivalence"], 1 << (2 * k));
    }
}

TEST(BenchPlot, MeasuresEachOrderAndWritesTheSvg) {
    TempDir dir;
    const std::string svg = dir.file("scaling.svg");
    const ChildResult r = pcsg({"bench", "--plot", svg, "--plot-orders", "2,3", "--width", "32",
                                "--height", "24", "--threads", "2", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j.size(), 2u);
    EXPECT_EQ(j[0]["order"], 2);
    EXPECT_GT(j[1]["native"]["peak_rss_bytes"].get<double>(), 1e6);
    if (inPath("povray")) {
        EXPECT_TRUE(j[1].contains("povray")) << r.out;
    }
    EXPECT_EQ(readFile(svg).rfind("<svg", 0), 0u);
    EXPECT_EQ(pcsg({"bench", "--plot", svg, "--plot-orders", "5,3"}).exitCode, 2);
}

}  // namespace
}  // namespace pcsg::tools
