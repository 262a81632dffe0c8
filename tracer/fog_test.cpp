// POV-Ray 3.7's constant and ground fog (fog.h), against its formulas by hand.
#include "fog.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pcsg::tracer {
namespace {

TEST(Fog, ConstantFogBlendsByExpOfDepthOverDistance) {
    Fog f;
    f.enabled = true;
    f.distance = 4;
    f.color = {0.5, 0.6, 0.7};
    const FogEffect e = fogAlong(f, {0, 0, 0}, {0, 1, 0}, 8);
    const double a = std::exp(-2.0);
    EXPECT_NEAR(e.attenuation.x, a, 1e-15);
    EXPECT_NEAR(e.add.y, 0.6 * (1 - a), 1e-15);
    // A ray that hits nothing: fully fogged.
    const FogEffect miss = fogAlong(f, {0, 0, 0}, {0, 1, 0}, kFogMissDepth);
    EXPECT_EQ(miss.attenuation.x, 0.0);
    EXPECT_NEAR(miss.add.z, 0.7, 1e-15);
    // No fog: nothing changes.
    Fog none;
    const FogEffect n = fogAlong(none, {0, 0, 0}, {0, 1, 0}, 8);
    EXPECT_EQ(n.attenuation.x, 1.0);
    EXPECT_EQ(n.add.x, 0.0);
}

TEST(Fog, FilterTintsAndTransmitKeepsAMinimum) {
    Fog f;
    f.enabled = true;
    f.distance = 1;
    f.color = {0.2, 0.4, 0.8};
    f.filter = 0.5;
    f.transmit = 0.25;
    const FogEffect e = fogAlong(f, {0, 0, 0}, {1, 0, 0}, 100);  // exp(-100) < transmit
    EXPECT_NEAR(e.attenuation.x, 0.25 * (0.5 + 0.5 * 0.2), 1e-15);
    EXPECT_NEAR(e.attenuation.z, 0.25 * (0.5 + 0.5 * 0.8), 1e-15);
    EXPECT_NEAR(e.add.y, 0.75 * 0.4, 1e-15);
}

TEST(Fog, GroundFogDensityAlongZ) {
    Fog f;
    f.enabled = true;
    f.type = 2;
    f.distance = 2;
    f.offset = 1;
    f.alt = 0.5;
    // Below the offset all along: constant fog.
    EXPECT_NEAR(fogTransmittance(f, {0, 0, 0}, {1, 0, 0}, 3), std::exp(-1.5), 1e-15);
    // Level at height h above the offset: density 1 / (1 + h^2), h in fog_alt units.
    const double h = (2.0 - 1) / 0.5;
    EXPECT_NEAR(fogTransmittance(f, {0, 0, 2}, {1, 0, 0}, 3), std::exp(-3 / (1 + h * h) / 2),
                1e-15);
    // Rising from below the offset to above: (atan e - s) / (e - s).
    const Vec3 d = normalize(Vec3{1, 0, 1});
    const double depth = 4, s = (0.5 - 1) / 0.5, e = (0.5 + depth * d.z - 1) / 0.5;
    EXPECT_NEAR(fogTransmittance(f, {0, 0, 0.5}, d, depth),
                std::exp(-depth * ((std::atan(e) - s) / (e - s)) / 2), 1e-14);
    // Both above, at different heights: (atan s - atan e) / (s - e).
    const double s2 = (1.5 - 1) / 0.5, e2 = (1.5 + depth * d.z - 1) / 0.5;
    EXPECT_NEAR(fogTransmittance(f, {0, 0, 1.5}, d, depth),
                std::exp(-depth * ((std::atan(s2) - std::atan(e2)) / (s2 - e2)) / 2), 1e-14);
    // Looking up from the ground at the sky: a finite amount of fog over an infinite ray.
    const double up = fogTransmittance(f, {0, 0, 0}, normalize(Vec3{0, 1, 1}), kFogMissDepth);
    EXPECT_GT(up, 0.0);
    EXPECT_LT(up, 1.0);
}

}  // namespace
}  // namespace pcsg::tracer
