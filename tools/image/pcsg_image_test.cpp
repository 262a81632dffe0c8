// The pcsg-image helper as a program: `write` turns linear floats on standard input into
// .png (8-bit sRGB), .tif (16-bit sRGB) and .exr (linear float) files that OpenImageIO
// reads back with the expected values, and fails cleanly (exit 2, nothing left behind);
// `compare` prints the metrics as JSON and writes the report's images.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "cli_test_util.h"
#include "image_test_util.h"

namespace pcsg::tools {
namespace {

using testing::filesIn;
using testing::pcsgImage;
using testing::readBack;
using testing::TempDir;

// A 3x2 image whose values cover the cases: black, white, mid-grey, clamping above 1 and
// below 0, the linear segment of sRGB near 0.
const int kW = 3, kH = 2;
const std::vector<float> kPixels = {
    0.0f, 0.5f,   1.0f, /**/ 0.2f, 2.0f,  -1.0f, /**/ 0.001f, 0.05f, 0.5f,
    1.0f, 0.001f, 0.2f, /**/ 0.5f, 0.05f, 0.0f,  /**/ 0.2f,   0.2f,  0.2f,
};
// The same values sRGB-encoded, worked out independently of the code under test
// (1.055 * v^(1/2.4) - 0.055, or 12.92 * v below 0.0031308, times 255 or 65535, rounded).
const std::vector<int> k8Bit = {0,   188, 255, 124, 255, 0, 3,   63,  188,
                                255, 3,   124, 188, 63,  0, 124, 124, 124};
const std::vector<int> k16Bit = {0,     48192, 65535, 31754, 65535, 0, 847,   16240, 48192,
                                 65535, 847,   31754, 48192, 16240, 0, 31754, 31754, 31754};

std::span<const std::byte> bytesOf(const std::vector<float>& v) {
    return std::as_bytes(std::span(v));
}

TEST(PcsgImageWrite, PngIsEightBitSrgb) {
    TempDir dir;
    const std::string out = dir.file("img.png");
    const ChildResult r = pcsgImage({"write", out, "3", "2"}, bytesOf(kPixels));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.err, "");
    OIIO::ImageSpec spec;
    const auto px = readBack<uint8_t>(out, OIIO::TypeDesc::UINT8, spec);
    EXPECT_EQ(spec.width, kW);
    EXPECT_EQ(spec.height, kH);
    EXPECT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT8);
    ASSERT_EQ(px.size(), k8Bit.size());
    for (size_t i = 0; i < px.size(); ++i) EXPECT_EQ(px[i], k8Bit[i]) << "value " << i;
    EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"img.png"});
}

TEST(PcsgImageWrite, TiffIsSixteenBitSrgb) {
    TempDir dir;
    for (const char* name : {"img.tif", "IMG.TIFF"}) {
        const std::string out = dir.file(name);
        const ChildResult r = pcsgImage({"write", out, "3", "2"}, bytesOf(kPixels));
        ASSERT_EQ(r.exitCode, 0) << r.err;
        OIIO::ImageSpec spec;
        const auto px = readBack<uint16_t>(out, OIIO::TypeDesc::UINT16, spec);
        EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT16) << name;
        ASSERT_EQ(px.size(), k16Bit.size());
        for (size_t i = 0; i < px.size(); ++i)
            EXPECT_EQ(px[i], k16Bit[i]) << name << " value " << i;
    }
}

TEST(PcsgImageWrite, ExrKeepsLinearFloatsExactly) {
    TempDir dir;
    const std::string out = dir.file("img.exr");
    const ChildResult r = pcsgImage({"write", out, "3", "2"}, bytesOf(kPixels));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    OIIO::ImageSpec spec;
    const auto px = readBack<float>(out, OIIO::TypeDesc::FLOAT, spec);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(px, kPixels);  // nothing clamped or encoded, -1 and 2 included
}

TEST(PcsgImageWrite, TruncatedInputIsAnErrorAndLeavesNothing) {
    TempDir dir;
    const std::string out = dir.file("img.png");
    const auto bytes = bytesOf(kPixels);
    const ChildResult r = pcsgImage({"write", out, "3", "2"}, bytes.first(bytes.size() - 5));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("cannot write '" + out + "'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("standard input ended after 67 of 72 bytes"), std::string::npos) << r.err;
    EXPECT_TRUE(filesIn(dir.path()).empty());
}

TEST(PcsgImageWrite, TooMuchInputIsAnErrorToo) {
    TempDir dir;
    const std::string out = dir.file("img.png");
    // A 3x2 image was sent where 2x2 was announced: the sizes disagree.
    const ChildResult r = pcsgImage({"write", out, "2", "2"}, bytesOf(kPixels));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("more than the 48 bytes"), std::string::npos) << r.err;
    EXPECT_TRUE(filesIn(dir.path()).empty());
}

TEST(PcsgImageWrite, AFailedWriteKeepsTheOldImage) {
    TempDir dir;
    const std::string out = dir.file("img.png");
    ASSERT_EQ(pcsgImage({"write", out, "3", "2"}, bytesOf(kPixels)).exitCode, 0);
    const std::string before = testing::readFile(out);
    const ChildResult r = pcsgImage({"write", out, "3", "2"}, bytesOf(kPixels).first(10));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(testing::readFile(out), before);
    EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"img.png"});
}

TEST(PcsgImageWrite, AnUnknownExtensionIsAClearError) {
    TempDir dir;
    const std::string out = dir.file("img.jpg");
    const ChildResult r = pcsgImage({"write", out, "3", "2"}, bytesOf(kPixels));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("unknown image type '.jpg'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(".png"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(".exr"), std::string::npos) << r.err;
    EXPECT_TRUE(filesIn(dir.path()).empty());
}

TEST(PcsgImageWrite, AMissingDirectoryIsAnError) {
    TempDir dir;
    const std::string out = dir.file("no/such/dir/img.png");
    const ChildResult r = pcsgImage({"write", out, "3", "2"}, bytesOf(kPixels));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("cannot write '" + out + "'"), std::string::npos) << r.err;
    EXPECT_TRUE(filesIn(dir.path()).empty());
}

TEST(PcsgImageWrite, BadSizesAreErrors) {
    TempDir dir;
    for (const std::vector<std::string>& size :
         {std::vector<std::string>{"0", "2"}, {"3", "-1"}, {"100000", "2"}}) {
        const ChildResult r =
            pcsgImage({"write", dir.file("img.png"), size[0], size[1]}, bytesOf(kPixels));
        EXPECT_EQ(r.exitCode, 2) << size[0] << "x" << size[1];
        EXPECT_NE(r.err.find("image size"), std::string::npos) << r.err;
    }
    const ChildResult r = pcsgImage({"write", dir.file("img.png"), "three", "2"}, bytesOf(kPixels));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_TRUE(filesIn(dir.path()).empty());
}

// Two solid-colour PNGs of the given size (linear values).
std::string solidPng(const TempDir& dir, const std::string& name, int w, int h, float v) {
    const std::vector<float> px(static_cast<size_t>(w) * h * 3, v);
    const std::string path = dir.file(name);
    const ChildResult r =
        pcsgImage({"write", path, std::to_string(w), std::to_string(h)}, bytesOf(px));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return path;
}

TEST(PcsgImageCompare, EqualImagesAgree) {
    TempDir dir;
    const std::string a = solidPng(dir, "a.png", 8, 6, 0.3f);
    const std::string b = solidPng(dir, "b.png", 8, 6, 0.3f);
    const ChildResult r =
        pcsgImage({"compare", a, b, "--ss", "2", "--heatmap", dir.file("d.png"), "--reduced-a",
                   dir.file("ra.png"), "--reduced-b", dir.file("rb.png")},
                  {});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["agree"], true);
    EXPECT_EQ(j["psnr"], "inf");
    EXPECT_EQ(j["mean_abs_error"], 0.0);
    EXPECT_EQ(j["a"]["width"], 8);
    EXPECT_EQ(j["b"]["height"], 6);
    EXPECT_EQ(j["width"], 4);  // reduced by 2
    EXPECT_EQ(j["height"], 3);
    for (const char* name : {"d.png", "ra.png", "rb.png"}) {
        OIIO::ImageSpec spec;
        readBack<uint8_t>(dir.file(name), OIIO::TypeDesc::UINT8, spec);
        EXPECT_EQ(spec.width, 4) << name;
        EXPECT_EQ(spec.height, 3) << name;
    }
}

TEST(PcsgImageCompare, DifferentImagesDiffer) {
    TempDir dir;
    const std::string a = solidPng(dir, "a.png", 8, 6, 0.3f);
    const std::string b = solidPng(dir, "b.png", 8, 6, 0.6f);
    const ChildResult r = pcsgImage({"compare", a, b}, {});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["agree"], false);
    EXPECT_DOUBLE_EQ(j["share_off"].get<double>(), 1.0);
    // The thresholds are passed through: a lenient enough comparison agrees.
    const ChildResult lenient =
        pcsgImage({"compare", a, b, "--pixel-threshold", "0.5", "--max-mean-error", "0.5"}, {});
    EXPECT_EQ(lenient.exitCode, 0) << lenient.out;
}

TEST(PcsgImageCompare, DifferentSizesCannotBeCompared) {
    TempDir dir;
    const std::string a = solidPng(dir, "a.png", 8, 6, 0.3f);
    const std::string b = solidPng(dir, "b.png", 6, 8, 0.3f);
    const ChildResult r = pcsgImage({"compare", a, b}, {});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("sizes differ"), std::string::npos) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["b"]["width"], 6);
    EXPECT_FALSE(j.contains("agree"));
}

TEST(PcsgImageCompare, AMissingFileCannotBeCompared) {
    TempDir dir;
    const std::string a = solidPng(dir, "a.png", 8, 6, 0.3f);
    const ChildResult r = pcsgImage({"compare", a, dir.file("none.png")}, {});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("none.png"), std::string::npos) << r.err;
}

TEST(PcsgImage, HelpNamesBothSubcommands) {
    const ChildResult r = pcsgImage({"--help"}, {});
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_NE(r.out.find("write"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("compare"), std::string::npos) << r.out;
    const ChildResult w = pcsgImage({"write", "--help"}, {});
    EXPECT_EQ(w.exitCode, 0);
    EXPECT_NE(w.out.find("standard input"), std::string::npos) << w.out;
    EXPECT_EQ(pcsgImage({}, {}).exitCode, 2);  // a subcommand is required
}

}  // namespace
}  // namespace pcsg::tools
