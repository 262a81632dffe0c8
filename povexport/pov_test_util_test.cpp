// The POV-Ray runner of the povexport tests tries a run again when POV-Ray's threads
// timed out, and only then. A stand-in `povray` on PATH plays each case.
#include "pov_test_util.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace pcsg::povtest {
namespace {

namespace fs = std::filesystem;

// A fake povray that reads its scene's one word: "always" times out every time, "flaky"
// times out on its first two runs, and anything else renders one red pixel. Each run
// appends a line to state/<word>, so the test can count them.
class FakePovray : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::path(::testing::TempDir()) / ("pcsg_fake_pov_" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "bin");
        fs::create_directories(dir_ / "state");
        const fs::path script = dir_ / "bin" / "povray";
        std::ofstream(script) << "#!/bin/sh\n"
                                 "kind=$(cat scene.pov)\n"
                                 "echo x >> '"
                              << (dir_ / "state").string()
                              << "'/\"$kind\"\n"
                                 "n=$(wc -l < '"
                              << (dir_ / "state").string()
                              << "'/\"$kind\")\n"
                                 "if [ \"$kind\" = always ] || { [ \"$kind\" = flaky ] && "
                                 "[ \"$n\" -lt 3 ]; }; then\n"
                                 "  echo 'Timed out waiting for worker thread startup'; exit 1\n"
                                 "fi\n"
                                 "printf 'P6\\n1 1\\n255\\n\\377\\000\\000' > out.ppm\n";
        fs::permissions(script, fs::perms::owner_all);
        oldPath_ = std::getenv("PATH") ? std::getenv("PATH") : "";
        ::setenv("PATH", ((dir_ / "bin").string() + ":" + oldPath_).c_str(), 1);
    }
    void TearDown() override {
        ::setenv("PATH", oldPath_.c_str(), 1);
        fs::remove_all(dir_);
    }
    int runsOf(const std::string& kind) const {
        std::ifstream in(dir_ / "state" / kind);
        int n = 0;
        for (std::string line; std::getline(in, line);) ++n;
        return n;
    }
    fs::path dir_;
    std::string oldPath_;
};

TEST_F(FakePovray, ARunWhoseThreadsTimedOutIsTriedAgainAndOthersAreNot) {
    const std::vector<PovRun> runs =
        renderPovMany({PovJob{"fine", "fine", 1, 1}, PovJob{"flaky", "flaky", 1, 1}});
    ASSERT_EQ(runs.size(), 2u);
    EXPECT_EQ(runsOf("fine"), 1);
    EXPECT_EQ(runsOf("flaky"), 3);
    for (const PovRun& run : runs) {
        EXPECT_EQ(run.status, 0) << run.log;
        EXPECT_FALSE(povThreadsTimedOut(run));
        ASSERT_EQ(run.rgb.size(), 3u);
        EXPECT_EQ(run.at(0, 0, 0), 255);
        EXPECT_EQ(run.at(0, 0, 1), 0);
    }
}

TEST_F(FakePovray, ARunThatKeepsTimingOutIsReturnedAsItFailed) {
    const PovRun run = renderPovMany({PovJob{"always", "always", 1, 1}}, 2).front();
    EXPECT_EQ(runsOf("always"), 3);
    EXPECT_NE(run.status, 0);
    EXPECT_TRUE(povThreadsTimedOut(run));
    EXPECT_TRUE(run.rgb.empty());
}

}  // namespace
}  // namespace pcsg::povtest
