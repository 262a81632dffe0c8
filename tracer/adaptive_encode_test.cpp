#include "adaptive_encode.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace pcsg::tracer {
namespace {

// The memo must give aaEncode's double bit for bit, whatever it remembered before: values
// that share a slot (the table has 512), repeats, and the special values.
TEST(AaEncodeMemo, GivesAaEncodesBitsWhateverItRemembered) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> colour(0.0f, 1.5f);
    std::vector<float> values;
    for (int i = 0; i < 20000; ++i) values.push_back(colour(rng));
    // Repeats, as a sky's pixels are, and after others have overwritten their slots.
    for (int i = 0; i < 2000; ++i) values.push_back(values[static_cast<size_t>(i) * 7]);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (float v : {0.0f, -0.0f, -0.25f, 1.0f, 1e-30f, 3.4e38f, nan, -nan,
                    std::bit_cast<float>(0xffffffffu), std::bit_cast<float>(0x7f800000u)})
        values.push_back(v);
    AaEncodeMemo memo;
    for (float v : values) {
        const double want = aaEncode(v);
        EXPECT_EQ(std::bit_cast<uint64_t>(memo(v)), std::bit_cast<uint64_t>(want)) << v;
    }
}

// The first value asked for in a fresh memo, for every slot's starting bits and others.
TEST(AaEncodeMemo, AFreshMemoIsRightFirstTime) {
    for (float v : {0.5f, 0.0f, std::bit_cast<float>(0xffffffffu), 2.0f}) {
        AaEncodeMemo memo;
        EXPECT_EQ(std::bit_cast<uint64_t>(memo(v)), std::bit_cast<uint64_t>(aaEncode(v))) << v;
    }
}

// The encoded distance of two colours in three channels.
double encodedDistance(const float* a, const float* b) {
    const double ea[3] = {aaEncode(a[0]), aaEncode(a[1]), aaEncode(a[2])};
    const double eb[3] = {aaEncode(b[0]), aaEncode(b[1]), aaEncode(b[2])};
    return colourDistance(ea, eb);
}

// Whatever NearColours calls near must be below the threshold once encoded: random pairs
// at and around the bound, the worst case (0 against the bound in every channel, where the
// encoded distance is half the threshold: a bound of (T/3)^2.5 would reach T), and
// negative values; NaN and infinities are near only to their own bits (the encoded
// distance is then 0 or NaN, which never reaches the threshold either).
TEST(NearColours, NearColoursNeverDifferAtTheThreshold) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> colour(-0.1f, 1.2f), unit(0.0f, 1.0f);
    for (double t : {0.3, 0.05, 1.0, 2.5}) {
        const NearColours near(t);
        ASSERT_GT(near.bound(), 0.0);
        float m = static_cast<float>(near.bound());  // the largest float within the bound
        if (m > near.bound()) m = std::nextafter(m, 0.0f);
        const float zero[3] = {0, 0, 0}, worst[3] = {m, m, m};
        ASSERT_TRUE(near(zero, worst));
        EXPECT_LT(encodedDistance(zero, worst), t);
        EXPECT_GT(encodedDistance(zero, worst), 0.45 * t);  // the bound is not far too small
        int nearPairs = 0;
        for (int i = 0; i < 200000; ++i) {
            float a[3], b[3];
            for (int k = 0; k < 3; ++k) {
                a[k] = i % 2 ? colour(rng) : unit(rng) * m;  // half of them near zero
                b[k] = a[k] + (unit(rng) * 2.2f - 1.1f) * m;
            }
            if (!near(a, b)) continue;
            ++nearPairs;
            ASSERT_LT(encodedDistance(a, b), t) << a[0] << " " << b[0];
        }
        EXPECT_GT(nearPairs, 10000);
    }
    const NearColours near(0.3);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const float a[3] = {0.5f, 0.5f, 0.5f};
    for (float v : {nan, inf, -inf}) {
        const float b[3] = {0.5f, v, 0.5f}, c[3] = {0.5f, v, 0.5000001f};
        EXPECT_FALSE(near(a, b)) << v;
        EXPECT_FALSE(near(b, c)) << v;
        EXPECT_TRUE(near(b, b)) << v;
        EXPECT_FALSE(encodedDistance(b, b) >= 0.3) << v;
    }
    EXPECT_TRUE(near(a, a));
    const float a2[3] = {0.5f, 0.5f, std::nextafter(0.5f, 1.0f)};
    EXPECT_TRUE(near(a, a2));
    EXPECT_FALSE(NearColours(1e-9)(a, a2));  // no margin left: encode unless the same bits
    EXPECT_TRUE(NearColours(1e-9)(a, a));
}

// The render's decision with the shortcut is the reference decision on the centres:
// Render.AdaptiveSupersamplingChangesOnlyPixelsNextToAContrast (render_test.cpp).

TEST(AaEncode, IsPovRaysGammaOfTwoPointFive) {
    EXPECT_DOUBLE_EQ(aaEncode(1.0), 1.0);
    EXPECT_DOUBLE_EQ(aaEncode(0.0), 0.0);
    EXPECT_DOUBLE_EQ(aaEncode(-1.0), 0.0);
    EXPECT_NEAR(aaEncode(0.5), 0.757858283, 1e-9);
    const double a[3] = {0.1, 0.5, 0.9}, b[3] = {0.2, 0.4, 0.9};
    EXPECT_NEAR(colourDistance(a, b), 0.2, 1e-15);
}

}  // namespace
}  // namespace pcsg::tracer
