// `--clock X` of render, export-pov and verify (docs/language.md section 11): the still at
// that time. It changes the image and the exported text, a non-finite clock is a wrong
// command line (exit status 2), and a directive value that is bad at that time is a
// run-time error of the scene (exit status 1) that names the clock.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli_test_util.h"

namespace pcsg::tools {
namespace {

using testing::pcsg;
using testing::readFile;
using testing::TempDir;

const char* kMoving =
    "camera { location <4*cos(clock*360 - 90), 4*sin(clock*360 - 90), 2>  look_at <0,0,0> }\n"
    "move(clock * 2 - 1, 0, 0) uscale(0.5) sphere\n";

std::string renderAt(const TempDir& dir, const std::string& scene, const std::string& name,
                     const std::string& clock) {
    const std::string out = dir.file(name);
    std::vector<std::string> args = {"render", scene,      "-o", out,         "--width",
                                     "32",     "--height", "24", "--threads", "2"};
    if (!clock.empty()) {
        args.push_back("--clock");
        args.push_back(clock);
    }
    const ChildResult r = pcsg(args);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return readFile(out);
}

TEST(ClockOption, ChangesTheImageAndZeroIsTheDefault) {
    TempDir dir;
    const std::string scene = dir.write("m.pcsg", kMoving);
    const std::string still = renderAt(dir, scene, "still.png", "");
    const std::string zero = renderAt(dir, scene, "zero.png", "0");
    const std::string half = renderAt(dir, scene, "half.png", "0.5");
    EXPECT_FALSE(still.empty());
    EXPECT_EQ(still, zero);
    EXPECT_NE(still, half);
}

TEST(ClockOption, ExportPovBakesTheFramesValuesIn) {
    TempDir dir;
    const std::string scene = dir.write("m.pcsg", kMoving);
    for (const char* clock : {"0", "0.25"}) {
        const ChildResult r = pcsg(
            {"export-pov", scene, "-o", dir.file(std::string(clock) + ".pov"), "--clock", clock});
        ASSERT_EQ(r.exitCode, 0) << r.err;
    }
    const std::string a = readFile(dir.file("0.pov")), b = readFile(dir.file("0.25.pov"));
    EXPECT_NE(a, b);
    EXPECT_EQ(b.find("clock"), std::string::npos);  // numbers only
}

TEST(ClockOption, ANonFiniteClockIsAWrongCommandLine) {
    TempDir dir;
    const std::string scene = dir.write("m.pcsg", kMoving);
    for (const char* cmd : {"render", "export-pov"}) {
        for (const char* clock : {"nan", "inf", "-inf", "1e999", "x"}) {
            const std::string out = dir.file(std::string(cmd) == "render" ? "o.png" : "o.pov");
            const ChildResult r = pcsg({cmd, scene, "-o", out, "--clock", clock});
            EXPECT_EQ(r.exitCode, 2) << cmd << " --clock " << clock << "\n" << r.err;
            EXPECT_NE(r.err.find("--clock"), std::string::npos) << r.err;
            EXPECT_FALSE(std::filesystem::exists(out));
        }
    }
}

TEST(ClockOption, ABadDirectiveValueAtThatTimeIsARunTimeError) {
    TempDir dir;
    const std::string scene =
        dir.write("a.pcsg", "camera { location <0, -5, 2> angle 40 + clock * 200 }\nsphere\n");
    const std::string out = dir.file("a.png");
    EXPECT_EQ(pcsg({"render", scene, "-o", out, "--width", "8", "--height", "6"}).exitCode, 0);
    std::filesystem::remove(out);
    const ChildResult r =
        pcsg({"render", scene, "-o", out, "--width", "8", "--height", "6", "--clock", "0.75"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("clock 0.75"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace pcsg::tools
