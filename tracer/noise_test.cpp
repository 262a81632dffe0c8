// Properties of the noise, the noise patterns and the normal perturbations that hold
// whatever POV-Ray's exact values are (those are checked against povray itself in
// noise_povray_test.cpp): ranges, determinism across threads, POV-Ray's 4096-cell period,
// how turbulence is built from the noise, the defaults table and the wave forms.
#include "noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "noise_patterns.h"
#include "noise_tables.h"
#include "normal_patterns.h"

namespace pcsg {
namespace {

std::vector<Vec3> randomPoints(size_t n, double range, unsigned seed = 7) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-range, range);
    std::vector<Vec3> pts(n);
    for (Vec3& p : pts) p = Vec3{u(rng), u(rng), u(rng)};
    return pts;
}

TEST(Noise, StaysInZeroOneWithMeanNearOneHalf) {
    double sum = 0, lo = 1, hi = 0;
    const auto pts = randomPoints(20000, 50);
    for (const Vec3& p : pts) {
        const double v = noise(p);
        ASSERT_GE(v, 0.0);
        ASSERT_LE(v, 1.0);
        sum += v;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    const double mean = sum / pts.size();
    EXPECT_NEAR(mean, 0.5, 0.06);
    EXPECT_LT(lo, 0.15);  // the range correction spreads the values over most of [0, 1]
    EXPECT_GT(hi, 0.85);
}

TEST(Noise, RepeatsEvery4096CellsLikePovRays) {
    // POV-Ray's lattice index is (floor + 10000) & 0xFFF: the noise repeats every 4096
    // units along each axis (for coordinates that stay exact when shifted).
    for (const Vec3& p : randomPoints(200, 20)) {
        const Vec3 q{std::round(p.x * 64) / 64, std::round(p.y * 64) / 64,
                     std::round(p.z * 64) / 64};
        EXPECT_EQ(noise(q), noise(q + Vec3{4096, 0, 0}));
        EXPECT_EQ(noise(q), noise(q + Vec3{0, -4096, 0}));
        EXPECT_EQ(noise(q), noise(q + Vec3{0, 0, 8192}));
        EXPECT_EQ(dnoise(q), dnoise(q + Vec3{4096, 4096, 4096}));
        EXPECT_NE(noise(q), noise(q + Vec3{2048, 0, 0}));
    }
}

TEST(Noise, HashTableIsAPermutationRepeatedOnce) {
    const auto h = noise_detail::hashTable();
    std::vector<int> seen(4096, 0);
    for (int i = 0; i < 4096; ++i) {
        ASSERT_LT(h[i], 4096);
        ++seen[h[i]];
        EXPECT_EQ(h[i], h[4096 + i]);
    }
    for (int count : seen) EXPECT_EQ(count, 1);
    int fixed = 0;  // a shuffle, not the identity
    for (int i = 0; i < 4096; ++i) fixed += h[i] == i;
    EXPECT_LT(fixed, 20);
}

TEST(Noise, IsContinuousAcrossCellFaces) {
    for (double x : {-3.0, -1.0, 0.0, 1.0, 7.0}) {
        const Vec3 a{x - 1e-9, 0.3, 0.6}, b{x + 1e-9, 0.3, 0.6};
        EXPECT_NEAR(noise(a), noise(b), 1e-6);
        EXPECT_NEAR(dnoise(a).x, dnoise(b).x, 1e-6);
    }
}

TEST(Noise, SameValuesOnEveryThread) {
    const auto pts = randomPoints(5000, 100, 11);
    std::vector<std::vector<double>> results(4);
    std::vector<std::thread> threads;
    for (auto& r : results)
        threads.emplace_back([&pts, &r] {
            Turbulence t;
            NormalSpec ripples;
            ripples.kind = NormalKind::Ripples;
            for (const Vec3& p : pts) {
                r.push_back(noise(p));
                r.push_back(dnoise(p).y);
                r.push_back(turbulence(p, t));
                r.push_back(perturbNormal(ripples, p, {0, 0, 1}).x);
            }
        });
    for (auto& th : threads) th.join();
    for (size_t i = 1; i < results.size(); ++i) EXPECT_EQ(results[i], results[0]);
}

TEST(Turbulence, IsTheOctaveSumOfTheNoise) {
    Turbulence t;
    t.octaves = 1;
    const Vec3 p{0.37, -1.2, 2.9};
    const double n = noise(p);
    EXPECT_DOUBLE_EQ(turbulence(p, t), std::clamp(2 * n - 0.5, 0.0, 1.0));
    EXPECT_EQ(dturbulence(p, t), dnoise(p));
    t.octaves = 3;
    t.omega = 0.4;
    t.lambda = 3.0;
    const double expected = std::clamp(2 * n - 0.5, 0.0, 1.0) + 0.4 * (2 * noise(p * 3.0) - 0.5) +
                            0.16 * (2 * noise(p * 9.0) - 0.5);
    EXPECT_NEAR(turbulence(p, t), expected, 1e-15);
    const Vec3 d = dnoise(p) + dnoise(p * 3.0) * 0.4 + dnoise(p * 9.0) * 0.16;
    const Vec3 got = dturbulence(p, t);
    EXPECT_NEAR(got.x, d.x, 1e-15);
    EXPECT_NEAR(got.z, d.z, 1e-15);
}

TEST(Turbulence, WarpMovesByAmountTimesDTurbulence) {
    Turbulence t;
    const Vec3 p{1.5, 0.25, -0.75};
    EXPECT_EQ(turbulenceWarp(t, p), p);  // no amount: no warp
    t.amount = {0.5, 0, 2};
    const Vec3 d = dturbulence(p, t);
    const Vec3 q = turbulenceWarp(t, p);
    EXPECT_DOUBLE_EQ(q.x, p.x + 0.5 * d.x);
    EXPECT_DOUBLE_EQ(q.y, p.y);
    EXPECT_DOUBLE_EQ(q.z, p.z + 2 * d.z);
}

TEST(NoiseWavesTest, TenUnitSourcesWithPovRaysFrequencies) {
    const NoiseWaves& w = noiseWaves();
    for (int i = 0; i < NoiseWaves::kCount; ++i) {
        EXPECT_NEAR(dot(w.source[i], w.source[i]), 1.0, 1e-12);
        EXPECT_GE(w.frequency[i], 0.01);
        EXPECT_LT(w.frequency[i], 1.01);
        for (int j = 0; j < i; ++j) EXPECT_NE(w.source[i], w.source[j]);
    }
    EXPECT_EQ(&w, &noiseWaves());  // built once
}

TEST(NoisePatterns, RawValuesInZeroOne) {
    PatternSpec s;
    s.turbulence.amount = {0.7, 0.7, 0.7};
    for (PatternKind k : {PatternKind::Bozo, PatternKind::Granite, PatternKind::Agate,
                          PatternKind::Wrinkles, PatternKind::Dents}) {
        s.kind = k;
        for (const Vec3& p : randomPoints(2000, 10)) {
            const double v = noisePatternValue(s, p);
            ASSERT_GE(v, 0.0) << static_cast<int>(k);
            ASSERT_LE(v, 1.0) << static_cast<int>(k);
        }
    }
    s.kind = PatternKind::Checker;
    EXPECT_EQ(noisePatternValue(s, {0.5, 0.5, 0.5}), 0.0);
}

TEST(NoisePatterns, WoodAndMarbleWithoutTurbulence) {
    PatternSpec s;
    s.kind = PatternKind::Wood;
    EXPECT_DOUBLE_EQ(noisePatternValue(s, {3, 4, 9}), 5.0);  // distance from the z axis
    s.kind = PatternKind::Marble;
    EXPECT_DOUBLE_EQ(noisePatternValue(s, {0.25, 4, 9}), 0.25);  // x
    s.turbulence.amount = {0.5, 0.5, 0.5};
    const Vec3 p{0.25, 4, 9};
    EXPECT_DOUBLE_EQ(noisePatternValue(s, p), 0.25 + 0.5 * turbulence(p, s.turbulence));
}

TEST(NoisePatterns, TurbulenceChangesTheValue) {
    PatternSpec a, b;
    a.kind = b.kind = PatternKind::Bozo;
    b.turbulence.amount = {0.5, 0.5, 0.5};
    const Vec3 p{0.3, 0.6, 0.9};
    EXPECT_NE(noisePatternValue(a, p), noisePatternValue(b, p));
    EXPECT_EQ(noisePatternValue(b, p), noise(turbulenceWarp(b.turbulence, p)));
}

TEST(WaveForms, PovRaysFoldAndShapes) {
    EXPECT_EQ(waveValue(1.0, 1.0, 0.0, WaveForm::Ramp), 1.0);  // fmod by 1.00001, not 1
    EXPECT_NEAR(waveValue(0.3, 2.0, 0.1, WaveForm::Ramp), 0.7, 1e-12);
    EXPECT_NEAR(waveValue(0.8, 2.0, 0.0, WaveForm::Ramp), 0.6 - 0.00001, 1e-12);
    EXPECT_NEAR(waveValue(-0.3, 1.0, 0.0, WaveForm::Ramp), 0.7, 1e-12);  // negative wraps
    EXPECT_EQ(waveValue(2.5, 0.0, 0.3, WaveForm::Ramp), 2.5);            // frequency 0: untouched
    EXPECT_NEAR(waveValue(0.25, 1.0, 0.0, WaveForm::Triangle), 0.5, 1e-12);
    EXPECT_NEAR(waveValue(0.75, 1.0, 0.0, WaveForm::Triangle), 0.5, 1e-12);
    EXPECT_NEAR(waveValue(0.25, 1.0, 0.0, WaveForm::Sine), 1.0, 1e-12);
    EXPECT_NEAR(waveValue(0.5, 1.0, 0.0, WaveForm::Scallop), 1.0, 1e-12);
    EXPECT_NEAR(waveValue(0.5, 1.0, 0.0, WaveForm::Cubic), 0.5, 1e-12);
    EXPECT_NEAR(cycloidal(0.25), 1.0, 1e-12);
    EXPECT_NEAR(cycloidal(-0.25), -1.0, 1e-12);
    EXPECT_NEAR(cycloidal(3.125), std::sin(0.125 * 2 * M_PI), 1e-12);
    EXPECT_NEAR(triangleWave(-0.25), 0.5, 1e-12);
}

TEST(PatternDefaultsTable, PovRaysDefaults) {
    EXPECT_EQ(patternDefaults(PatternKind::Wood).wave, WaveForm::Triangle);
    EXPECT_EQ(patternDefaults(PatternKind::Marble).wave, WaveForm::Triangle);
    EXPECT_EQ(patternDefaults(PatternKind::Bozo).wave, WaveForm::Ramp);
    EXPECT_EQ(patternDefaults(PatternKind::Gradient).wave, WaveForm::Ramp);
    for (PatternKind k : {PatternKind::Checker, PatternKind::Brick, PatternKind::Hexagon})
        EXPECT_FALSE(patternDefaults(k).continuous);
    EXPECT_TRUE(patternDefaults(PatternKind::Leopard).continuous);
    EXPECT_TRUE(patternDefaults(PatternKind::Agate).turbulenceInside);
    EXPECT_FALSE(patternDefaults(PatternKind::Gradient).turbulenceInside);
    EXPECT_EQ(patternDefaults(PatternKind::Bozo).colourMap.size(), 6u);
    EXPECT_EQ(patternDefaults(PatternKind::Bozo, true).colourMap.size(), 2u);  // spotted
    EXPECT_EQ(patternDefaults(PatternKind::Granite).colourMap.back().colour.rgb, (Vec3{1, 1, 1}));
    EXPECT_EQ(patternDefaults(PatternKind::Checker).colourMap[0].colour.rgb, (Vec3{0, 0, 1}));
    EXPECT_EQ(patternDefaults(PatternKind::Hexagon).colourMap.size(), 3u);
    EXPECT_EQ(patternDefaults(PatternKind::Agate).colourMap.size(), 6u);
    EXPECT_TRUE(patternDefaults(PatternKind::Plain).colourMap.empty());
}

TEST(NormalPatterns, UnitResultsAndNoChangeWithoutAmount) {
    const Vec3 n{0, 0, 1};
    EXPECT_EQ(perturbNormal(NormalSpec{}, {1, 2, 3}, n), n);  // NormalKind::None
    for (NormalKind k : {NormalKind::Bumps, NormalKind::Dents, NormalKind::Wrinkles,
                         NormalKind::Ripples, NormalKind::Waves}) {
        NormalSpec s;
        s.kind = k;
        for (const Vec3& p : randomPoints(200, 5)) {
            const Vec3 r = perturbNormal(s, p, n);
            EXPECT_NEAR(dot(r, r), 1.0, 1e-12);
        }
        s.amount = 0;
        const Vec3 r = perturbNormal(s, {0.3, 0.2, 0.1}, n);
        EXPECT_NEAR(r.z, 1.0, 1e-15);
    }
}

TEST(NormalPatterns, BumpsAddAmountTimesDNoise) {
    NormalSpec s;
    s.kind = NormalKind::Bumps;
    s.amount = 0.3;
    const Vec3 p{0.4, 1.7, -0.2}, n{0, 1, 0};
    const Vec3 want = n + dnoise(p) * 0.3;
    const Vec3 got = perturbNormal(s, p, n);
    const Vec3 unitWant = want / std::sqrt(dot(want, want));
    EXPECT_NEAR(got.x, unitWant.x, 1e-15);
    EXPECT_NEAR(got.y, unitWant.y, 1e-15);
    EXPECT_NEAR(got.z, unitWant.z, 1e-15);
}

TEST(NormalPatterns, ThroughAScaledPatternUsesTheTransposedMaps) {
    // A pattern scaled by 0.5 along x: the same bumps at half the size. Through the maps,
    // the point is doubled in x and the normal's tilt along x doubles on the way back.
    NormalSpec s;
    s.kind = NormalKind::Bumps;
    const Affine from = Affine::scale({0.5, 1, 1}), to = from.inverse();
    const Vec3 p{0.3, 0.7, 0.1}, n{0, 0, 1};
    const Vec3 inPattern = perturbNormal(s, to.point(p), n);
    const Vec3 back = perturbNormalThrough(s, to, from, true, p, n);
    const Vec3 want = Vec3{inPattern.x * 2, inPattern.y, inPattern.z};
    const Vec3 unitWant = want / std::sqrt(dot(want, want));
    EXPECT_NEAR(back.x, unitWant.x, 1e-12);
    EXPECT_NEAR(back.z, unitWant.z, 1e-12);
    EXPECT_EQ(perturbNormalThrough(s, to, from, false, p, n), perturbNormal(s, p, n));
}

}  // namespace
}  // namespace pcsg
