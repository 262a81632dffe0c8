// Shading against POV-Ray 3.7's classic formulas, computed by hand (shading.h lists them):
// ambient + diffuse (N.L) + phong (R.L)^phong_size per light, only ambient in shadow,
// + r * the colour of the reflected ray, at most max_trace_level (5) rays deep and not
// below adc_bailout.
#include "shading.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "bounds.h"
#include "test_support.h"
#include "traversal.h"

namespace pcsg::tracer {
namespace {

using testing::compile;

struct Lit {
    std::unique_ptr<testing::Compiled> compiled;
    std::unique_ptr<TraceScene> scene;
    std::unique_ptr<Shader> shader;
};

Lit make(const char* text) {
    Lit l;
    l.compiled = compile(text);
    if (!l.compiled->graph) return l;
    const Graph& g = *l.compiled->graph;
    l.scene = std::make_unique<TraceScene>(g, computeBounds(g));
    l.shader = std::make_unique<Shader>(*l.scene);
    return l;
}

void expectColour(const Vec3& got, const Vec3& want, const char* what, double tol = 1e-12) {
    EXPECT_NEAR(got.x, want.x, tol) << what;
    EXPECT_NEAR(got.y, want.y, tol) << what;
    EXPECT_NEAR(got.z, want.z, tol) << what;
}

// A unit sphere at the origin, one coloured light, a material with every finish item.
const char* kSphere = R"(
light      { position <4, -6, 5>  color <0.9, 0.8, 0.7> }
background <0.05, 0.1, 0.2>
material m { color <0.8, 0.5, 0.3>  ambient 0.15  diffuse 0.65  phong 0.4  phong_size 25 }
paint(m) sphere
)";

TEST(Shading, SphereIsAmbientPlusDiffusePlusPhong) {
    Lit l = make(kSphere);
    ASSERT_TRUE(l.shader);
    const Vec3 light{4, -6, 5}, lc{0.9, 0.8, 0.7}, colour{0.8, 0.5, 0.3};
    const double ambient = 0.15, diffuse = 0.65, phong = 0.4, size = 25;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    int lit = 0, dark = 0, highlights = 0;
    for (int i = 0; i < 400; ++i) {
        // A camera ray from a random point outside at a random point of the sphere's
        // visible side.
        Vec3 eye{u(rng), u(rng), u(rng)};
        eye = normalize(eye) * (3 + 2 * std::fabs(u(rng)));
        Vec3 onSphere{u(rng), u(rng), u(rng)};
        onSphere = normalize(onSphere);
        if (dot(onSphere, eye - onSphere) <= 0.05) continue;  // facing away from the eye
        const Vec3 d = normalize(onSphere - eye);
        // Where the ray enters the sphere (it may be a little before onSphere).
        const double b = dot(eye, d), cc = dot(eye, eye) - 1;
        const double t = -b - std::sqrt(b * b - cc);
        const Vec3 p = eye + d * t;
        const Vec3 n = normalize(p);  // the outward normal faces the ray here
        const Vec3 L = normalize(light - p);
        Vec3 want = colour * ambient;
        const double nl = dot(n, L);
        if (nl > 0) {
            // The sphere is convex: nothing else can shadow a point facing the light.
            want += mul(lc, colour) * (diffuse * nl);
            const Vec3 r = d - n * (2 * dot(d, n));
            const double rl = dot(r, L);
            if (rl > 0) {
                want += lc * (phong * std::pow(rl, size));
                if (std::pow(rl, size) > 0.1) ++highlights;
            }
            ++lit;
        } else {
            ++dark;
        }
        expectColour(l.shader->shade(Ray{eye, d}), want, "sphere", 1e-9);
    }
    EXPECT_GT(lit, 50);
    EXPECT_GT(dark, 50);
    EXPECT_GT(highlights, 0);
    // A ray that misses gets the background.
    expectColour(l.shader->shade(Ray{{0, -5, 0}, normalize(Vec3{0.5, 1, 0})}), {0.05, 0.1, 0.2},
                 "background");
}

TEST(Shading, APointInShadowGetsOnlyAmbient) {
    // A floor lit from straight above, and a ball floating between the light and the floor.
    Lit l = make(R"(
light      { position <0, 0, 10>  color <1, 1, 1> }
material ground { color <0.6, 0.7, 0.8>  ambient 0.2  diffuse 0.7  phong 0.5  phong_size 5 }
material ball  { color <1, 0, 0> }
paint(ground) plane ∪ paint(ball) move(0, 0, 3) sphere
)");
    ASSERT_TRUE(l.shader);
    const Vec3 colour{0.6, 0.7, 0.8};
    const double ambient = 0.2, diffuse = 0.7, phong = 0.5;
    const Vec3 eye{0, -8, 1};
    for (double x : {-0.5, 0.0, 0.4}) {
        // Under the ball: in its shadow.
        const Vec3 p{x, 0.2, 0};
        const Ray ray{eye, normalize(p - eye)};
        expectColour(l.shader->shade(ray), colour * ambient, "in shadow");
    }
    for (double x : {-3.0, 2.5}) {
        // Beside it: lit. N = +z, L from p to the light.
        const Vec3 p{x, 0.5, 0};
        const Vec3 d = normalize(p - eye), n{0, 0, 1};
        const Vec3 L = normalize(Vec3{0, 0, 10} - p);
        Vec3 want = colour * ambient + colour * (diffuse * dot(n, L));
        const Vec3 r = d - n * (2 * dot(d, n));
        if (dot(r, L) > 0) want += Vec3{1, 1, 1} * (phong * std::pow(dot(r, L), 5));
        expectColour(l.shader->shade(Ray{eye, d}), want, "lit");
    }
}

TEST(Shading, ReflectionAddsRTimesTheReflectedColour) {
    // A mirror floor (diffuse 0, so its own colour is ambient only) and a red ball that
    // the reflected ray sees; a ray past the ball sees the background in the mirror.
    Lit l = make(R"(
light      { position <0, -10, 20>  color <1, 1, 1> }
background <0.1, 0.2, 0.3>
material mirror { color <0.5, 0.5, 0.5>  ambient 0.1  diffuse 0  reflection 0.6 }
material ball   { color <1, 0, 0>  ambient 0.3  diffuse 0.5 }
paint(mirror) plane ∪ paint(ball) move(0, 3, 1.5) sphere
)");
    ASSERT_TRUE(l.shader);
    const Vec3 eye{0, -4, 2};
    const Vec3 mirrorLocal = Vec3{0.5, 0.5, 0.5} * 0.1;
    // Towards the floor at (0, 1, 0): reflected up, the ray meets the ball on its underside,
    // which faces away from the light: the ball's ambient colour only.
    {
        const Vec3 p{0, 1, 0};
        const Vec3 d = normalize(p - eye);
        const Vec3 r = normalize(Vec3{d.x, d.y, -d.z});
        const Vec3 ballAmbient{0.3, 0, 0};
        expectColour(l.shader->shade(Ray{p, r}), ballAmbient, "what the reflected ray sees");
        expectColour(l.shader->shade(Ray{eye, d}), mirrorLocal + ballAmbient * 0.6,
                     "ball in mirror");
    }
    // Towards the floor at (3, 0.5, 0): reflected into the sky.
    {
        const Vec3 p{3, 0.5, 0};
        const Vec3 d = normalize(p - eye);
        expectColour(l.shader->shade(Ray{eye, d}), mirrorLocal + Vec3{0.1, 0.2, 0.3} * 0.6,
                     "sky in mirror");
    }
}

// Two parallel mirrors, z <= 0 and z >= 2, and a ray bouncing between them for ever. Each
// bounce adds ambient * colour * r^k (diffuse 0: the lights do not matter).
double betweenMirrors(double reflection) {
    const std::string text = "material m { color <1, 1, 1>  ambient 0.2  diffuse 0  reflection " +
                             std::to_string(reflection) + " }\n" +
                             "paint(m) (plane ∪ move(0, 0, 2) flipxy plane)\n";
    auto c = compile(text);
    if (!c->graph) return -1;
    const Graph& g = *c->graph;
    TraceScene scene(g, computeBounds(g));
    Shader shader(scene);
    const Vec3 col = shader.shade(Ray{{0, 0, 1}, normalize(Vec3{1, 0.3, -1})});
    EXPECT_EQ(col.x, col.y);
    return col.x;
}

TEST(Shading, ReflectionStopsAfterMaxTraceLevelFive) {
    // r = 0.9: the weights 1, 0.9, ..., 0.9^4 stay above adc_bailout, so exactly five rays
    // are traced: the camera ray and four reflections.
    const double r = 0.9;
    double five = 0, six = 0;
    for (int k = 0; k < 6; ++k) {
        if (k < 5) five += 0.2 * std::pow(r, k);
        six += 0.2 * std::pow(r, k);
    }
    const double got = betweenMirrors(r);
    EXPECT_NEAR(got, five, 1e-12);
    EXPECT_GT(std::fabs(got - six), 0.1);
}

TEST(Shading, ReflectionStopsBelowAdcBailout) {
    // r = 0.1: the third reflection would have weight 0.001 < 1/255: three rays only.
    EXPECT_NEAR(betweenMirrors(0.1), 0.2 * (1 + 0.1 + 0.01), 1e-12);
}

// POV-Ray's empirical Fresnel term of metallic highlights, at the angle of cosine c.
double metallicF(double c) {
    const double x = std::acos(c) / (std::numbers::pi / 2);
    return std::clamp(0.014567225 / ((x - 1.12) * (x - 1.12)) - 0.011612903, 0.0, 1.0);
}

// Section 10's finish on a sphere: brilliance, specular with roughness, and metallic phong
// and specular highlights tinted by the pigment, each computed here from its definition.
TEST(Shading, BrillianceSpecularAndMetallicHighlights) {
    Lit l = make(R"(
light      { position <4, -6, 5>  color <0.9, 0.8, 0.7> }
material m { pigment { color rgb <0.8, 0.5, 0.3> }
             finish { ambient 0.15 diffuse 0.65 brilliance 2.5 phong 0.4 phong_size 25
                      specular 0.6 roughness 0.04 metallic 0.7 } }
paint(m) sphere
)");
    ASSERT_TRUE(l.shader);
    const Vec3 light{4, -6, 5}, lc{0.9, 0.8, 0.7}, colour{0.8, 0.5, 0.3};
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> u(-1, 1);
    int specular = 0;
    for (int i = 0; i < 400; ++i) {
        Vec3 eye = normalize(Vec3{u(rng), u(rng), u(rng)}) * (3 + 2 * std::fabs(u(rng)));
        const Vec3 onSphere = normalize(Vec3{u(rng), u(rng), u(rng)});
        if (dot(onSphere, eye - onSphere) <= 0.05) continue;
        const Vec3 d = normalize(onSphere - eye);
        const double b = dot(eye, d), cc = dot(eye, eye) - 1;
        const Vec3 p = eye + d * (-b - std::sqrt(b * b - cc));
        const Vec3 n = normalize(p), L = normalize(light - p);
        Vec3 want = colour * 0.15;
        const double nl = dot(n, L);
        if (nl > 0) {
            want += mul(lc, colour) * (0.65 * std::pow(nl, 2.5));
            const double k = 0.7 * (1 - metallicF(nl));
            const Vec3 tinted = mul(
                lc, Vec3{1 + k * (colour.x - 1), 1 + k * (colour.y - 1), 1 + k * (colour.z - 1)});
            const double rl = dot(d - n * (2 * dot(d, n)), L);
            if (rl > 0) want += tinted * (0.4 * std::pow(rl, 25));
            const Vec3 h = normalize(L - d);  // halfway between light and viewer
            const double nh = dot(n, h);
            if (nh > 0) want += tinted * (0.6 * std::pow(nh, 1 / 0.04));
            if (nh > 0 && std::pow(nh, 25) > 0.1) ++specular;
        }
        expectColour(l.shader->shade(Ray{eye, d}), want, "sphere", 1e-9);
    }
    EXPECT_GT(specular, 0);
}

// reflection { min, max }: min looking straight down, max at grazing angles, (1 - cos)
// between; with fresnel, the Fresnel reflectance of a dielectric of the interior's ior
// (computed here from the s and p polarisations); metallic tints it by the pigment.
TEST(Shading, ReflectionRangeFresnelAndMetallic) {
    const auto floorColour = [](const char* finish, double cosI) {
        const std::string text = std::string("background <0.2, 0.4, 0.8>\n") +
                                 "material f { pigment { color rgb <1, 0.5, 0.25> } finish { "
                                 "ambient 0 diffuse 0 " +
                                 finish + " } interior { ior 1.5 } }\npaint(f) plane\n";
        auto c = compile(text);
        EXPECT_TRUE(c->graph) << c->diags.format();
        if (!c->graph) return Vec3{};
        TraceScene scene(*c->graph, computeBounds(*c->graph));
        Shader shader(scene);
        const double sinI = std::sqrt(1 - cosI * cosI);
        return shader.shade(Ray{{0, 0, 1}, Vec3{sinI, 0, -cosI}});
    };
    const Vec3 sky{0.2, 0.4, 0.8};
    for (double cosI : {1.0, 0.8, 0.5, 0.2, 0.05}) {
        const double frac = 1 - cosI;
        const double plain = cosI == 1.0 ? 0.1 : frac * 0.7 + (1 - frac) * 0.1;
        expectColour(floorColour("reflection { 0.1, 0.7 }", cosI), sky * plain, "range");
        const double n = 1.5, sinT = std::sqrt(1 - cosI * cosI) / n;
        const double cosT = std::sqrt(1 - sinT * sinT);
        const double rs = std::pow((cosI - n * cosT) / (cosI + n * cosT), 2);
        const double rp = std::pow((n * cosI - cosT) / (n * cosI + cosT), 2);
        const double f = (rs + rp) / 2;
        expectColour(floorColour("reflection { 0.1, 0.7 fresnel on }", cosI),
                     sky * (f * 0.7 + (1 - f) * 0.1), "fresnel");
        const double k = 1 - metallicF(cosI);
        const Vec3 tint{1, 1 + k * (0.5 - 1), 1 + k * (0.25 - 1)};
        expectColour(floorColour("reflection { 0.1, 0.7 metallic }", cosI), mul(sky, tint) * plain,
                     "metallic");
    }
}

}  // namespace
}  // namespace pcsg::tracer
