// pcsg fuzz: a short campaign's JSON (its shape, and that its counts add up to what the
// exit status says), that a seed gives the same systems twice, and bad arguments.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_util.h"
#include "coverage.h"

namespace pcsg::tools {
namespace {

using testing::pcsg;
using testing::TempDir;

TEST(FuzzCommand, JsonOfAShortCampaign) {
    if (!inPath("povray")) GTEST_SKIP() << "POV-Ray is not installed";
    TempDir dir;
    const ChildResult r =
        pcsg({"fuzz", "--count", "2", "--seed", "0x5eed", "--width", "32", "--height", "24",
              "--threads", "1", "--json", "--out", dir.path(), "--shrink-tries", "3"});
    ASSERT_TRUE(r.exitCode == 0 || r.exitCode == 1) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);  // stdout holds the object alone
    EXPECT_EQ(j["seed"].get<uint64_t>(), 0x5eedu);
    EXPECT_EQ(j["systems"].get<int>(), 2);
    const int agree = j["agree"].get<int>();
    const auto& disagree = j["disagree"];
    ASSERT_TRUE(disagree.is_array());
    EXPECT_EQ(agree + int(disagree.size()), 2);
    EXPECT_EQ(r.exitCode, disagree.empty() ? 0 : 1);
    for (const auto& c : disagree) {
        const std::string d = c.get<std::string>();
        for (const char* f :
             {"shrunk.pcsg", "original.pcsg", "native.png", "povray.png", "diff.png", "what.txt"})
            EXPECT_TRUE(std::filesystem::exists(d + "/" + f)) << d << "/" << f;
    }
    const auto& cov = j["coverage"];
    ASSERT_TRUE(cov.is_object());
    EXPECT_EQ(cov.size(), fuzz::featureNames().size());
    int used = 0;
    for (const std::string& f : fuzz::featureNames()) {
        ASSERT_TRUE(cov.contains(f)) << f;
        const int n = cov[f].get<int>();
        EXPECT_GE(n, 0);
        EXPECT_LE(n, 2);
        used += n;
    }
    EXPECT_GT(used, 4);  // two systems use some features
    // One line per system on stderr.
    EXPECT_NE(r.err.find("system 0 (seed"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("system 1 (seed"), std::string::npos) << r.err;
}

// Thresholds that no pair of images can meet (a negative mean error) make every system
// differ: exit status 1, and a shrunk case with everything in it.
TEST(FuzzCommand, ADisagreementLeavesAShrunkCase) {
    if (!inPath("povray")) GTEST_SKIP() << "POV-Ray is not installed";
    TempDir dir;
    const ChildResult r =
        pcsg({"fuzz", "--count", "1", "--seed", "7", "--width", "32", "--height", "24", "--threads",
              "1", "--max-mean-error", "-1", "--json", "--out", dir.path(), "--shrink-tries", "4"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["agree"].get<int>(), 0);
    ASSERT_EQ(j["disagree"].size(), 1u);
    const std::string c = j["disagree"][0].get<std::string>();
    EXPECT_EQ(c, dir.path() + "/case-1");
    for (const char* f :
         {"shrunk.pcsg", "original.pcsg", "native.png", "povray.png", "diff.png", "what.txt"})
        EXPECT_TRUE(std::filesystem::exists(c + "/" + f)) << f;
    const std::string shrunk = testing::readFile(c + "/shrunk.pcsg");
    EXPECT_LT(shrunk.size(), testing::readFile(c + "/original.pcsg").size());
    EXPECT_NE(testing::readFile(c + "/what.txt").find("the images differ"), std::string::npos);
    // The generated system is the one --generate-only writes for the same seed.
    const ChildResult g = pcsg(
        {"fuzz", "--generate-only", "--count", "1", "--seed", "7", "--out", dir.path() + "/gen"});
    ASSERT_EQ(g.exitCode, 0) << g.err;
    EXPECT_EQ(testing::readFile(dir.path() + "/gen/system-0.pcsg"),
              testing::readFile(c + "/original.pcsg"));
}

TEST(FuzzCommand, BadArgumentsAreExitStatusTwo) {
    const ChildResult seed = pcsg({"fuzz", "--seed", "banana", "--count", "1"});
    EXPECT_EQ(seed.exitCode, 2);
    EXPECT_NE(seed.err.find("--seed"), std::string::npos) << seed.err;
    EXPECT_EQ(pcsg({"fuzz", "--count", "0"}).exitCode, 2);
    EXPECT_EQ(pcsg({"fuzz", "--width", "-3"}).exitCode, 2);
    const ChildResult help = pcsg({"fuzz", "--help"});
    EXPECT_EQ(help.exitCode, 0);
    EXPECT_NE(help.out.find("--minutes"), std::string::npos);
}

}  // namespace
}  // namespace pcsg::tools
