// The comparison behind pcsg verify: it must call equal images equal, see a real
// difference, forgive edge noise, and reduce exactly by block averages.
#include "image_compare.h"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <vector>

#include "heat_ramp.h"
#include "image_format.h"

namespace pcsg::tools {
namespace {

OIIO::ImageBuf solid(int w, int h, float r, float g, float b) {
    OIIO::ImageBuf img(OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::FLOAT));
    const float c[3] = {r, g, b};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) img.setpixel(x, y, c, 3);
    return img;
}

TEST(ImageCompare, IdenticalImagesAgreeExactly) {
    const auto a = solid(16, 12, 0.2f, 0.4f, 0.6f);
    const ImageMetrics m = compareImages(a, a, Thresholds{});
    EXPECT_TRUE(m.agree);
    EXPECT_EQ(m.meanAbsError, 0.0);
    EXPECT_EQ(m.maxError, 0.0);
    EXPECT_TRUE(std::isinf(m.psnr));
}

TEST(ImageCompare, AChangedMaterialDiffers) {
    const auto a = solid(16, 12, 0.2f, 0.4f, 0.6f);
    const auto b = solid(16, 12, 0.6f, 0.4f, 0.6f);
    const ImageMetrics m = compareImages(a, b, Thresholds{});
    EXPECT_FALSE(m.agree);
    EXPECT_DOUBLE_EQ(m.shareOff, 1.0);
    EXPECT_GT(m.maxError, 0.1);
}

TEST(ImageCompare, AFewEdgePixelsAreForgiven) {
    auto a = solid(100, 100, 0.2f, 0.2f, 0.2f);
    auto b = a;
    const float white[3] = {1, 1, 1};
    for (int i = 0; i < 50; ++i) b.setpixel(i, 0, white, 3);  // 0.5% of the pixels
    const ImageMetrics m = compareImages(a, b, Thresholds{});
    EXPECT_NEAR(m.shareOff, 0.005, 1e-12);
    EXPECT_TRUE(m.agree);
    EXPECT_EQ(m.maxY, 0);
    for (int i = 0; i < 200; ++i) b.setpixel(i % 100, 1 + i / 100, white, 3);  // now 2.5%
    EXPECT_FALSE(compareImages(a, b, Thresholds{}).agree);
}

TEST(ImageCompare, BoxReduceAveragesEachBlock) {
    OIIO::ImageBuf img(OIIO::ImageSpec(4, 2, 3, OIIO::TypeDesc::FLOAT));
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) {
            const float v[3] = {float(x + 4 * y), 0, 1};
            img.setpixel(x, y, v, 3);
        }
    const OIIO::ImageBuf r = boxReduce(img, 2);
    ASSERT_EQ(r.spec().width, 2);
    ASSERT_EQ(r.spec().height, 1);
    float p[3];
    r.getpixel(0, 0, p, 3);
    EXPECT_NEAR(p[0], (0 + 1 + 4 + 5) / 4.0, 1e-5);
    EXPECT_NEAR(p[2], 1.0, 1e-5);
    r.getpixel(1, 0, p, 3);
    EXPECT_NEAR(p[0], (2 + 3 + 6 + 7) / 4.0, 1e-5);
}

TEST(ImageCompare, PngRoundTripKeepsLinearValues) {
    const auto a = solid(8, 8, 0.05f, 0.5f, 1.0f);
    const std::string path =
        (std::filesystem::temp_directory_path() / "pcsg_image_compare_test.png").string();
    std::string error;
    ASSERT_TRUE(writeSrgbPng(a, path, error)) << error;
    OIIO::ImageBuf b;
    ASSERT_TRUE(readLinear(path, b, error)) << error;
    float p[3];
    b.getpixel(3, 3, p, 3);
    EXPECT_NEAR(p[0], 0.05, 0.005);
    EXPECT_NEAR(p[1], 0.5, 0.01);
    EXPECT_NEAR(p[2], 1.0, 1e-6);
    std::filesystem::remove(path);
}

// diff.png must show exactly the ramp the report's legend draws (heat_ramp.h): a row of
// differences from 0 past the full scale, each pixel's colour read back and compared.
TEST(ImageCompare, HeatMapDrawsTheLegendsRamp) {
    const int n = 121;
    const auto a = solid(n, 1, 0, 0, 0);
    OIIO::ImageBuf b = a;
    std::vector<float> d(n);
    for (int x = 0; x < n; ++x) {
        d[x] = 0.3f * float(x) / float(n - 1);  // sRGB-encoded difference in one channel
        const float v[3] = {0, float(srgbDecode(d[x])), 0};
        b.setpixel(x, 0, v, 3);
    }
    const OIIO::ImageBuf heat = diffHeatMap(a, b);
    for (int x = 0; x < n; ++x) {
        float p[3];
        heat.getpixel(x, 0, p, 3);
        const HeatRgb want = heatColour(d[x]);
        EXPECT_NEAR(srgbEncode(p[0]), want.r, 1e-4) << "d = " << d[x];
        EXPECT_NEAR(srgbEncode(p[1]), want.g, 1e-4) << "d = " << d[x];
        EXPECT_NEAR(srgbEncode(p[2]), want.b, 1e-4) << "d = " << d[x];
    }
    // And the ramp is the one described: black, red, yellow, white, white beyond.
    const auto at = [&](float dd) {
        const HeatRgb c = heatColour(dd);
        return std::array<float, 3>{c.r, c.g, c.b};
    };
    EXPECT_EQ(at(0), (std::array<float, 3>{0, 0, 0}));
    EXPECT_EQ(at(kHeatFullScale / 3), (std::array<float, 3>{1, 0, 0}));
    EXPECT_EQ(at(kHeatFullScale * 2 / 3), (std::array<float, 3>{1, 1, 0}));
    EXPECT_EQ(at(kHeatFullScale), (std::array<float, 3>{1, 1, 1}));
    EXPECT_EQ(at(1), (std::array<float, 3>{1, 1, 1}));
}

// The legend is a CSS linear-gradient through the stops, which interpolates linearly in
// sRGB values between them: heatColour must do the same for the legend to be exact.
TEST(ImageCompare, HeatRampIsLinearBetweenItsStops) {
    for (size_t i = 1; i < kHeatStops.size(); ++i) {
        const HeatStop& s0 = kHeatStops[i - 1];
        const HeatStop& s1 = kHeatStops[i];
        for (float t : {0.25f, 0.5f, 0.75f}) {
            const HeatRgb c = heatColour(kHeatFullScale * (s0.at + t * (s1.at - s0.at)));
            EXPECT_NEAR(c.r, s0.colour.r + t * (s1.colour.r - s0.colour.r), 1e-5);
            EXPECT_NEAR(c.g, s0.colour.g + t * (s1.colour.g - s0.colour.g), 1e-5);
            EXPECT_NEAR(c.b, s0.colour.b + t * (s1.colour.b - s0.colour.b), 1e-5);
        }
    }
    EXPECT_EQ(heatCssGradient(),
              "linear-gradient(to right,#000000 0.00%,#ff0000 33.33%,#ffff00 66.67%,"
              "#ffffff 100.00%)");
}

}  // namespace
}  // namespace pcsg::tools
