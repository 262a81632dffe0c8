#include "adaptive_encode.h"

#include <gtest/gtest.h>

#include <bit>
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
