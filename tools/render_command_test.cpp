// `pcsg render` run as a program: it renders in its own process and has pcsg-image write
// the file, so the image must come out whole (size, and the same pixels whichever format
// carries them), a scene with a run-time error must leave no image, and a missing
// helper must be named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "cli_test_util.h"
#include "image_format.h"

namespace pcsg::tools {
namespace {

using testing::filesIn;
using testing::pcsg;
using testing::TempDir;

// Figure 3a with a camera and a light, small enough to render in a moment.
const char* kScene =
    R"(camera { location <-1.8, -5.4, 2.3>  look_at <0.1, 0.1, 0.0>  sky <0, 0, 1>  angle 40 }
light  { position <12, -6, 8>  color <1, 1, 1> }
background <0.1, 0.2, 0.4>
{c=3} S
S if(c > 0, 2, 1)
1: S -> tetrahedron
2: S -> {c=c-1} ( move(0.5,0.5,0.5) uscale(0.5) S ∪
                  move(-0.5,-0.5,0.5) uscale(0.5) S ∪
                  move(0.5,-0.5,-0.5) uscale(0.5) S ∪
                  move(-0.5,0.5,-0.5) uscale(0.5) S )
)";

template <class T>
std::vector<T> readBack(const std::string& path, OIIO::TypeDesc type, OIIO::ImageSpec& spec) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        ADD_FAILURE() << "cannot open " << path << ": " << OIIO::geterror();
        return {};
    }
    spec = in->spec();
    std::vector<T> pixels(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, type, pixels.data())) << in->geterror();
    return pixels;
}

TEST(RenderCommand, WritesAPngOfTheRightSize) {
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kScene);
    const std::string out = dir.file("s.png");
    const ChildResult r =
        pcsg({"render", scene, "-o", out, "--width", "40", "--height", "30", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    OIIO::ImageSpec spec;
    const auto px = readBack<uint8_t>(out, OIIO::TypeDesc::UINT8, spec);
    EXPECT_EQ(spec.width, 40);
    EXPECT_EQ(spec.height, 30);
    EXPECT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT8);
    // Not a blank image: the background and the object are both there.
    ASSERT_FALSE(px.empty());
    EXPECT_NE(*std::min_element(px.begin(), px.end()), *std::max_element(px.begin(), px.end()));
    // The render's own peak RSS, and the writer's beside it.
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_GT(j.value("peak_rss_bytes", uint64_t{0}), 0u);
    EXPECT_GT(j.value("image_writer_peak_rss_bytes", uint64_t{0}), 0u);
    EXPECT_EQ(filesIn(dir.path()), (std::vector<std::string>{"s.pcsg", "s.png"}));
}

TEST(RenderCommand, PngAndExrCarryTheSamePixels) {
    // The EXR holds the render's linear floats as they were piped: encoded to 8-bit sRGB
    // they must be the PNG. A wrong byte order or row order on the pipe would not be.
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kScene);
    for (const char* name : {"s.png", "s.exr"})
        ASSERT_EQ(pcsg({"render", scene, "-o", dir.file(name), "--width", "24", "--height", "18",
                        "--threads", "2"})
                      .exitCode,
                  0)
            << name;
    OIIO::ImageSpec pngSpec, exrSpec;
    const auto png = readBack<uint8_t>(dir.file("s.png"), OIIO::TypeDesc::UINT8, pngSpec);
    const auto exr = readBack<float>(dir.file("s.exr"), OIIO::TypeDesc::FLOAT, exrSpec);
    ASSERT_EQ(png.size(), exr.size());
    ASSERT_EQ(png.size(), 24u * 18u * 3u);
    for (size_t i = 0; i < png.size(); ++i)
        ASSERT_EQ(png[i], std::lround(srgbEncode(exr[i]) * 255.0)) << "value " << i;
}

TEST(RenderCommand, ARunTimeErrorExitsOneAndWritesNothing) {
    TempDir dir;
    // The selection returns 3, and S has two rules.
    const std::string scene = dir.write("bad.pcsg",
                                        "{c=2} S\n"
                                        "S if(c > 0, 3, 1)\n"
                                        "1: S -> sphere\n"
                                        "2: S -> {c=c-1} uscale(0.5) S\n");
    const std::string out = dir.file("bad.png");
    const ChildResult r = pcsg({"render", scene, "-o", out, "--width", "16", "--height", "12"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("error"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"bad.pcsg"});
}

TEST(RenderCommand, AMissingImageHelperIsNamed) {
    // A copy of pcsg alone in a directory, with a PATH that has no pcsg-image either.
    TempDir dir;
    const std::string lonely = dir.file("pcsg");
    std::filesystem::copy_file(PCSG_EXECUTABLE, lonely);
    std::filesystem::permissions(lonely, std::filesystem::perms::owner_exec,
                                 std::filesystem::perm_options::add);
    const std::string scene = dir.write("s.pcsg", kScene);
    const std::string out = dir.file("s.png");
    const ChildResult r = runChild({"env", "PATH=" + dir.file("empty-bin"), lonely, "render", scene,
                                    "-o", out, "--width", "16", "--height", "12"});
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("pcsg-image is missing"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(RenderCommand, AnUnwritableOutputIsAnError) {
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kScene);
    const std::string out = dir.file("missing/s.png");
    const ChildResult r = pcsg({"render", scene, "-o", out, "--width", "16", "--height", "12"});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("cannot write '" + out + "'"), std::string::npos) << r.err;
    EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"s.pcsg"});
}

}  // namespace
}  // namespace pcsg::tools
