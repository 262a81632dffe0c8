// The noise, the noise patterns, the turbulence warp and the normal perturbations against
// POV-Ray 3.7 itself: povray renders a plane under an orthographic camera with 16-bit
// linear output (+FP16, File_Gamma=1.0), and each pixel must equal what our functions
// give at the point its centre sees, to within the 16-bit quantisation.
//
//  - Pigments: `finish { ambient 1 diffuse 0 }` and `color_map { [0 rgb 0] [1 rgb 1] }`,
//    so a pixel is the pattern's value after frequency, phase and wave (waveValue).
//  - Normals: a white plane, `finish { ambient 0 diffuse 1 }`, one parallel light, so a
//    pixel is max(0, N . L) with N the perturbed normal turned towards the camera.
//
// The camera: pixel (px, py)'s centre sees <cx + (x0) w, cy + (y0) h, planeZ> with
// x0 = (px + 0.5) / W - 0.5, y0 = 0.5 - (py + 0.5) / H (tracer/camera.h), w and h the
// lengths of `right` and `up`. Skipped when povray is not installed.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "noise.h"
#include "noise_patterns.h"
#include "normal_patterns.h"

namespace pcsg {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 64, kH = 48;
constexpr double kCx = 0.3, kCy = -0.2, kViewW = 6.0, kViewH = 4.5, kPlaneZ = 0.37;

Vec3 pixelPoint(int px, int py) {
    const double x0 = (px + 0.5) / kW - 0.5, y0 = 0.5 - (py + 0.5) / kH;
    return Vec3{kCx + x0 * kViewW, kCy + y0 * kViewH, kPlaneZ};
}

bool havePovray() {
    return std::system("command -v povray > /dev/null 2>&1") == 0;
}

// Reads a binary PPM (P6) with maxval 65535 (big-endian samples); returns the samples
// (r, g, b per pixel) scaled to [0, 1]. POV-Ray writes comment lines in the header.
std::vector<double> readPpm16(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::string magic;
    in >> magic;
    auto nextNumber = [&in] {
        in >> std::ws;
        while (in.peek() == '#') {
            std::string line;
            std::getline(in, line);
            in >> std::ws;
        }
        int v = 0;
        in >> v;
        return v;
    };
    const int w = nextNumber(), h = nextNumber(), maxval = nextNumber();
    in.get();
    if (magic != "P6" || w != kW || h != kH || maxval != 65535) return {};
    std::vector<unsigned char> bytes(static_cast<size_t>(w) * h * 6);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!in) return {};
    std::vector<double> samples(static_cast<size_t>(w) * h * 3);
    for (size_t i = 0; i < samples.size(); ++i)
        samples[i] = (bytes[i * 2] * 256 + bytes[i * 2 + 1]) / 65535.0;
    return samples;
}

fs::path workDir() {
    return fs::temp_directory_path() /
           ("pcsg_noise_povray_" + std::to_string(static_cast<long>(getpid())));
}

// Renders `objects` (a plane and its texture) with the test camera: r, g, b per pixel.
std::vector<double> renderPovRgb(const std::string& objects, const std::string& name) {
    const fs::path dir = workDir();
    fs::create_directories(dir);
    const fs::path pov = dir / (name + ".pov"), ppm = dir / (name + ".ppm");
    std::ofstream(pov) << "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                       << "camera { orthographic location <" << kCx << ", " << kCy
                       << ", 10> direction <0, 0, -1> right <" << kViewW << ", 0, 0> up <0, "
                       << kViewH << ", 0> }\n"
                       << objects << "\n";
    const std::string cmd = "povray +I" + pov.string() + " +O" + ppm.string() + " +W" +
                            std::to_string(kW) + " +H" + std::to_string(kH) +
                            " -A +FP16 -D File_Gamma=1.0 -GA > " + (dir / "log").string() + " 2>&1";
    if (std::system(cmd.c_str()) != 0) return {};
    return readPpm16(ppm);
}

// The red channel only (the grey images).
std::vector<double> renderPov(const std::string& objects, const std::string& name) {
    const std::vector<double> rgb = renderPovRgb(objects, name);
    std::vector<double> red(rgb.size() / 3);
    for (size_t i = 0; i < red.size(); ++i) red[i] = rgb[i * 3];
    return red;
}

// Compares POV-Ray's image with expected(point) pixel by pixel: every pixel within `tol`.
void expectImage(const std::string& objects, const std::string& name,
                 const std::function<double(const Vec3&)>& expected, double tol) {
    const std::vector<double> img = renderPov(objects, name);
    ASSERT_EQ(img.size(), static_cast<size_t>(kW * kH)) << "povray failed on " << name;
    double worst = 0;
    int bad = 0, worstX = 0, worstY = 0;
    for (int py = 0; py < kH; ++py)
        for (int px = 0; px < kW; ++px) {
            const double want = std::clamp(expected(pixelPoint(px, py)), 0.0, 1.0);
            const double d = std::fabs(img[py * kW + px] - want);
            if (d > tol) ++bad;
            if (d > worst) {
                worst = d;
                worstX = px;
                worstY = py;
            }
        }
    EXPECT_EQ(bad, 0) << name << ": " << bad << " pixels off by more than " << tol * 65535
                      << "/65535; worst " << worst * 65535 << "/65535 at (" << worstX << ", "
                      << worstY << ")";
    ::testing::Test::RecordProperty(name + "_worst_in_65535ths", std::to_string(worst * 65535));
}

// POV-Ray rounds to the nearest of 65536 levels (from single-precision colours): an exact
// value is within half a level, plus a little.
constexpr double kTol = 0.55 / 65535;

std::string greyPigment(const std::string& pattern) {
    return "plane { z, " + std::to_string(kPlaneZ) + " pigment { " + pattern +
           " color_map { [0 rgb 0] [1 rgb 1] } } finish { ambient 1 diffuse 0 } }";
}

PatternSpec spec(PatternKind kind, const Affine& fromPattern = Affine::identity()) {
    PatternSpec s;
    s.kind = kind;
    s.fromPattern = fromPattern;
    s.toPattern = fromPattern.inverse();
    return s;
}

// The value a pigment of this spec shows at a point of the plane.
double pigmentValue(const PatternSpec& s, const Vec3& p) {
    const double raw = noisePatternValue(s, s.toPattern.point(p));
    return waveValue(raw, s.frequency, s.phase, patternDefaults(s.kind).wave);
}

class NoisePovray : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!havePovray()) GTEST_SKIP() << "POV-Ray is not installed (apt-get install povray)";
    }
    static void TearDownTestSuite() {
        std::error_code ec;
        fs::remove_all(workDir(), ec);
    }
};

TEST_F(NoisePovray, BozoIsPovRaysNoise) {
    expectImage(
        greyPigment("bozo"), "bozo", [](const Vec3& p) { return noise(p); }, kTol);
}

TEST_F(NoisePovray, BozoScaledAndMoved) {
    const Affine m = Affine::translate({0.4, -1.3, 2.1}) * Affine::scale({0.3, 0.5, 0.7});
    const PatternSpec s = spec(PatternKind::Bozo, m);
    expectImage(
        greyPigment("bozo scale <0.3, 0.5, 0.7> translate <0.4, -1.3, 2.1>"), "bozo_moved",
        [&](const Vec3& p) { return pigmentValue(s, p); }, kTol);
}

TEST_F(NoisePovray, Granite) {
    const PatternSpec s = spec(PatternKind::Granite, Affine::scale({2, 2, 2}));
    expectImage(
        greyPigment("granite scale 2"), "granite",
        [&](const Vec3& p) { return pigmentValue(s, p); }, kTol);
}

TEST_F(NoisePovray, WoodWithTurbulence) {
    PatternSpec s = spec(PatternKind::Wood, Affine::scale({0.5, 0.5, 0.5}));
    s.turbulence.amount = {0.3, 0.3, 0.3};
    expectImage(
        greyPigment("wood turbulence 0.3 scale 0.5"), "wood",
        [&](const Vec3& p) { return pigmentValue(s, p); }, kTol);
}

TEST_F(NoisePovray, MarbleWithTurbulence) {
    PatternSpec s = spec(PatternKind::Marble);
    s.turbulence.amount = {0.8, 0.8, 0.8};
    expectImage(
        greyPigment("marble turbulence 0.8"), "marble",
        [&](const Vec3& p) { return pigmentValue(s, p); }, kTol);
}

TEST_F(NoisePovray, AgateDefault) {
    const PatternSpec s = spec(PatternKind::Agate, Affine::scale({0.7, 0.7, 0.7}));
    expectImage(
        greyPigment("agate scale 0.7"), "agate", [&](const Vec3& p) { return pigmentValue(s, p); },
        kTol);
}

TEST_F(NoisePovray, AgateWithTurbulenceAndAgateTurb) {
    PatternSpec s = spec(PatternKind::Agate);
    s.turbulence.amount = {0.4, 0.4, 0.4};
    s.agateTurb = 0.5;
    expectImage(
        greyPigment("agate agate_turb 0.5 turbulence 0.4"), "agate_turb",
        [&](const Vec3& p) { return pigmentValue(s, p); }, kTol);
}

TEST_F(NoisePovray, WrinklesWithTurbulence) {
    PatternSpec s = spec(PatternKind::Wrinkles, Affine::scale({0.6, 0.6, 0.6}));
    s.turbulence.amount = {0.2, 0.2, 0.2};
    expectImage(
        greyPigment("wrinkles turbulence 0.2 scale 0.6"), "wrinkles",
        [&](const Vec3& p) { return pigmentValue(s, p); }, kTol);
}

TEST_F(NoisePovray, Dents) {
    const PatternSpec s = spec(PatternKind::Dents, Affine::scale({0.4, 0.4, 0.4}));
    expectImage(
        greyPigment("dents scale 0.4"), "dents", [&](const Vec3& p) { return pigmentValue(s, p); },
        kTol);
}

// A magnifying glass: frequency 4096 multiplies any difference of the raw values by 4096
// before the 16-bit output, so agreement here means agreement to about 1e-9. Pixels whose
// folded value is within 0.002 of the fold (where a difference in the last bit may land
// on the other side of it) are not compared.
TEST_F(NoisePovray, BozoAndTurbulenceToNineDigits) {
    for (const char* name : {"bozo_x4096", "turb_x4096"}) {
        PatternSpec s = spec(PatternKind::Bozo, Affine::scale({0.7, 0.7, 0.7}));
        s.frequency = 4096;
        std::string text = "bozo frequency 4096 scale 0.7";
        if (std::string(name) == "turb_x4096") {
            s.turbulence.amount = {0.4, 0.4, 0.4};
            text = "bozo frequency 4096 turbulence 0.4 scale 0.7";
        }
        const std::vector<double> img = renderPov(greyPigment(text), name);
        ASSERT_EQ(img.size(), static_cast<size_t>(kW * kH));
        int compared = 0, bad = 0;
        for (int py = 0; py < kH; ++py)
            for (int px = 0; px < kW; ++px) {
                const double v = pigmentValue(s, pixelPoint(px, py));
                if (v < 0.002 || v > 0.998) continue;
                ++compared;
                if (std::fabs(img[py * kW + px] - v) > kTol) ++bad;
            }
        EXPECT_GT(compared, kW * kH * 9 / 10) << name;
        EXPECT_EQ(bad, 0) << name << ": " << bad << " of " << compared << " pixels differ";
    }
}

// POV-Ray's colour map lookup (pattern.cpp Search_Blend_Map, pigment.cpp Compute_Pigment):
// at or past the last entry its colour; else the first entry whose value is not below v
// and the one before it, interpolated (equal values: that entry's colour).
Vec3 mapColour(const std::vector<ColourMapEntry>& map, double v) {
    size_t c = 0, prev = 0;
    if (v >= map.back().value) {
        prev = c = map.size() - 1;
    } else {
        while (v > map[c].value) prev = c++;
    }
    if (v == map[c].value) prev = c;
    if (prev == c) return map[c].colour.rgb;
    const double f = (v - map[prev].value) / (map[c].value - map[prev].value);
    return map[prev].colour.rgb + (map[c].colour.rgb - map[prev].colour.rgb) * f;
}

// The raw values of checker and radial (pattern.cpp checker_pattern, radial_pattern), to
// check their default colours too; the patterns branch implements them for real.
double rawValue(const PatternSpec& s, const Vec3& q) {
    if (s.kind == PatternKind::Checker) {
        const double sum =
            std::floor(q.x + 1e-10) + std::floor(q.y + 1e-10) + std::floor(q.z + 1e-10);
        return (static_cast<long long>(sum) & 1) ? 1.0 : 0.0;
    }
    if (s.kind == PatternKind::Radial) return 0.25 + (std::atan2(q.x, q.z) + M_PI) / (2 * M_PI);
    return noisePatternValue(s, q);
}

// patternDefaults' colour maps (and waves) against POV-Ray's when the pigment has no
// color_map: bozo's own, spotted's grey, wood's, marble's, agate's, granite's grey,
// checker's blue and green, radial's.
TEST_F(NoisePovray, DefaultColourMaps) {
    struct Case {
        const char* text;
        PatternKind kind;
        bool spotted;
    };
    const Case cases[] = {
        {"bozo", PatternKind::Bozo, false},       {"spotted", PatternKind::Bozo, true},
        {"wood", PatternKind::Wood, false},       {"marble", PatternKind::Marble, false},
        {"agate", PatternKind::Agate, false},     {"granite", PatternKind::Granite, false},
        {"checker", PatternKind::Checker, false}, {"radial", PatternKind::Radial, false}};
    for (const Case& c : cases) {
        const PatternSpec s = spec(c.kind, Affine::scale({0.5, 0.5, 0.5}));
        const PatternDefaults d = patternDefaults(c.kind, c.spotted);
        const std::string name = std::string("map_") + c.text;
        const std::vector<double> img =
            renderPovRgb("plane { z, " + std::to_string(kPlaneZ) + " pigment { " + c.text +
                             " scale 0.5 } finish { ambient 1 diffuse 0 } }",
                         name);
        ASSERT_EQ(img.size(), static_cast<size_t>(kW * kH * 3)) << name;
        int bad = 0;
        for (int py = 0; py < kH; ++py)
            for (int px = 0; px < kW; ++px) {
                const Vec3 p = pixelPoint(px, py);
                const double raw = rawValue(s, s.toPattern.point(p));
                const double v = d.continuous ? waveValue(raw, 1, 0, d.wave) : raw;
                const Vec3 want = mapColour(d.colourMap, v);
                const double* got = &img[(py * kW + px) * 3];
                for (int k = 0; k < 3; ++k)
                    if (std::fabs(got[k] - std::clamp(want[k], 0.0, 1.0)) > kTol) ++bad;
            }
        EXPECT_EQ(bad, 0) << name << ": " << bad << " samples differ";
    }
}

// The turbulence warp with every modifier, applied after the pattern's transformations
// even when written before them.
TEST_F(NoisePovray, TurbulenceWarpWithModifiers) {
    PatternSpec s = spec(PatternKind::Bozo, Affine::scale({0.8, 0.8, 0.8}));
    s.turbulence.amount = {0.5, 0.3, 0.7};
    s.turbulence.octaves = 4;
    s.turbulence.omega = 0.6;
    s.turbulence.lambda = 2.5;
    const auto value = [&](const Vec3& p) { return pigmentValue(s, p); };
    expectImage(greyPigment("bozo turbulence <0.5, 0.3, 0.7> octaves 4 omega 0.6 lambda 2.5 "
                            "scale 0.8"),
                "turb_after", value, kTol);
    expectImage(greyPigment("bozo scale 0.8 turbulence <0.5, 0.3, 0.7> octaves 4 omega 0.6 "
                            "lambda 2.5"),
                "turb_before", value, kTol);
}

// turbulenceWarp on a pattern that is not noise-based: gradient x (raw value x, folded).
TEST_F(NoisePovray, TurbulenceWarpOnGradient) {
    Turbulence t;
    t.amount = {0.6, 0.6, 0.6};
    const auto value = [&](const Vec3& p) {
        const Vec3 q = turbulenceWarp(t, Affine::scale({2, 2, 2}).point(p));
        double g = q.x;
        if (g > 1.0) g = std::fmod(g, 1.0);
        return waveValue(g, 1.0, 0.0, WaveForm::Ramp);
    };
    expectImage(greyPigment("gradient x turbulence 0.6 scale 0.5"), "gradient_turb", value, kTol);
}

// Normals: a white plane lit by one parallel light from <1, 2, 3>, seen from above.
const Vec3 kToLight = Vec3{1, 2, 3} / std::sqrt(14.0);

std::string litPlane(const std::string& normal, bool facingDown = false) {
    const std::string z = std::to_string(kPlaneZ);
    return std::string("plane { ") + (facingDown ? "-z, -" : "z, ") + z +
           " pigment { rgb 1 } normal { " + normal +
           " } finish { ambient 0 diffuse 1 } }\n"
           "light_source { <1000, 2000, 3000> color rgb 1 parallel point_at <0, 0, 0> }";
}

// The diffuse light at a point, in POV-Ray's order (normal_patterns.h): the plane's normal
// turned towards the camera (looking down -z), then perturbed through the pattern's maps;
// the result is used as it is.
double litValue(const NormalSpec& n, const Vec3& p, const Vec3& planeNormal) {
    const Vec3 raw = planeNormal.z < 0 ? -planeNormal : planeNormal;
    const Vec3 r = perturbNormalThrough(n, n.pattern.toPattern, n.pattern.fromPattern,
                                        n.pattern.transformed, p, raw);
    return std::max(0.0, dot(r, kToLight));
}

NormalSpec normalSpec(NormalKind kind, double amount, const Affine& fromPattern) {
    NormalSpec n;
    n.kind = kind;
    n.amount = amount;
    n.pattern = spec(PatternKind::Plain, fromPattern);
    n.pattern.transformed = !(fromPattern == Affine::identity());
    return n;
}

Affine rotateZ(double degrees) {
    const double a = degrees * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
    Affine r;
    r.l[0][0] = c;
    r.l[0][1] = -s;
    r.l[1][0] = s;
    r.l[1][1] = c;
    return r;
}

TEST_F(NoisePovray, BumpsNormal) {
    const NormalSpec n = normalSpec(NormalKind::Bumps, 0.5, Affine::scale({0.2, 0.2, 0.2}));
    expectImage(
        litPlane("bumps 0.5 scale 0.2"), "bumps",
        [&](const Vec3& p) {
            return litValue(n, p, {0, 0, 1});
        },
        kTol);
}

// POV-Ray turns the plane's normal (-z here) towards the camera before perturbing it:
// perturbing -z and turning the result would mirror the bumps (every pixel differs).
TEST_F(NoisePovray, BumpsOnAPlaneFacingAway) {
    const NormalSpec n = normalSpec(NormalKind::Bumps, 0.5, Affine::scale({0.2, 0.2, 0.2}));
    expectImage(
        litPlane("bumps 0.5 scale 0.2", true), "bumps_down",
        [&](const Vec3& p) {
            return litValue(n, p, {0, 0, -1});
        },
        kTol);
}

TEST_F(NoisePovray, DentsNormal) {
    const NormalSpec n = normalSpec(NormalKind::Dents, 0.8, Affine::scale({0.3, 0.3, 0.3}));
    expectImage(
        litPlane("dents 0.8 scale 0.3"), "dents_normal",
        [&](const Vec3& p) {
            return litValue(n, p, {0, 0, 1});
        },
        kTol);
}

TEST_F(NoisePovray, WrinklesNormal) {
    const NormalSpec n = normalSpec(NormalKind::Wrinkles, 0.6, Affine::scale({0.4, 0.4, 0.4}));
    expectImage(
        litPlane("wrinkles 0.6 scale 0.4"), "wrinkles_normal",
        [&](const Vec3& p) {
            return litValue(n, p, {0, 0, 1});
        },
        kTol);
}

TEST_F(NoisePovray, RipplesNormalWithTurbulence) {
    NormalSpec n = normalSpec(NormalKind::Ripples, 0.5, Affine::scale({0.8, 0.8, 0.8}));
    n.pattern.frequency = 3;
    n.pattern.turbulence.amount = {0.2, 0.2, 0.2};
    expectImage(
        litPlane("ripples 0.5 frequency 3 turbulence 0.2 scale 0.8"), "ripples",
        [&](const Vec3& p) {
            return litValue(n, p, {0, 0, 1});
        },
        kTol);
}

TEST_F(NoisePovray, WavesNormalWithPhase) {
    NormalSpec n = normalSpec(NormalKind::Waves, 0.6, Affine::identity());
    n.pattern.frequency = 2;
    n.pattern.phase = 0.25;
    expectImage(
        litPlane("waves 0.6 frequency 2 phase 0.25"), "waves",
        [&](const Vec3& p) {
            return litValue(n, p, {0, 0, 1});
        },
        kTol);
}

// A non-uniform scale and a rotation: the normal goes into pattern space by M^T and back
// by M^-T, and the turbulence comes after both.
TEST_F(NoisePovray, BumpsThroughNonUniformRotatedPattern) {
    NormalSpec n = normalSpec(NormalKind::Bumps, 0.4, rotateZ(30) * Affine::scale({0.3, 0.6, 1.0}));
    n.pattern.turbulence.amount = {0.5, 0.5, 0.5};
    expectImage(
        litPlane("bumps 0.4 turbulence 0.5 scale <0.3, 0.6, 1> rotate 30*z"), "bumps_rotated",
        [&](const Vec3& p) {
            return litValue(n, p, {0, 0, 1});
        },
        kTol);
}

}  // namespace
}  // namespace pcsg
