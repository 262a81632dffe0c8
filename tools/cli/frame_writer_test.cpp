// The PNG files of a sequence, written on a thread beside the render (frame_writer.h).
#include "frame_writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_test_util.h"
#include "png_writer.h"

namespace pcsg::tools {
namespace {

using testing::filesIn;
using testing::readFile;
using testing::TempDir;

std::vector<float> gradient(int w, int h, float shift) {
    std::vector<float> rgb;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                rgb.push_back(std::fmod(shift + 0.01f * static_cast<float>(x * (c + 1) + y), 1.2f));
    return rgb;
}

// Two frames in turn, each collected before the next: the files writePng() writes, byte
// for byte, though the pixels were released as soon as start() returned.
TEST(FrameWriter, WritesTheFilesWritePngWrites) {
    TempDir dir;
    FrameWriter writer;
    EXPECT_FALSE(writer.busy());
    EXPECT_FALSE(writer.done().has_value());
    for (int f = 0; f < 2; ++f) {
        std::vector<float> rgb = gradient(37, 23, 0.3f * static_cast<float>(f));
        const std::string name = "f" + std::to_string(f) + ".png";
        writer.start(dir.file(name), 37, 23, rgb);
        EXPECT_TRUE(writer.busy());
        const std::vector<float> kept = rgb;
        rgb.assign(rgb.size(), 0.0f);  // start() must not read them any more
        const auto written = writer.done();
        ASSERT_TRUE(written.has_value());
        EXPECT_EQ(written->error, "");
        EXPECT_GE(written->seconds, 0.0);
        EXPECT_FALSE(writer.busy());
        writePng(dir.file("ref.png"), 37, 23, kept);
        EXPECT_EQ(readFile(dir.file(name)), readFile(dir.file("ref.png"))) << name;
    }
    EXPECT_EQ(filesIn(dir.path()), (std::vector<std::string>{"f0.png", "f1.png", "ref.png"}));
}

// A write that fails reports writePng's message through done(), not as an exception on
// the writer's thread, and leaves nothing behind.
TEST(FrameWriter, AFailedWriteIsReportedByDone) {
    TempDir dir;
    FrameWriter writer;
    writer.start(dir.file("no/such/dir/f.png"), 4, 4, gradient(4, 4, 0));
    const auto written = writer.done();
    ASSERT_TRUE(written.has_value());
    EXPECT_NE(written->error.find("cannot write '" + dir.file("no/such/dir/f.png") + "'"),
              std::string::npos)
        << written->error;
    EXPECT_TRUE(filesIn(dir.path()).empty());
}

// One file at a time: a second start() before the first was collected is refused.
TEST(FrameWriter, OneWriteAtATime) {
    TempDir dir;
    FrameWriter writer;
    writer.start(dir.file("a.png"), 4, 4, gradient(4, 4, 0));
    EXPECT_THROW(writer.start(dir.file("b.png"), 4, 4, gradient(4, 4, 0)), std::logic_error);
    ASSERT_TRUE(writer.done().has_value());
    EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"a.png"});
}

}  // namespace
}  // namespace pcsg::tools
