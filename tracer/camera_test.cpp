// The perspective camera of camera.h, on its own (PinholeCamera*) and against POV-Ray 3.7
// (PovrayCamera*).
//
// PinholeCamera*: the centre ray points at look_at; the rays through the left and right
// edges of the image are `angle` apart, those through the top and bottom edges follow from
// the aspect ratio; +x is on the right looking along +y with sky +z, and no other sky or
// viewing direction mirrors the image; directions are unit length; positions between
// pixel centres interpolate linearly in the image plane.
//
// PovrayCamera*: small emissive spheres (ambient 1, diffuse 0, so flat colours on black) at
// known scene positions, seen through several cameras, written once in POV-Ray's words with
// exactly the camera block that camera.h documents and once as a .pcsg scene with the same
// numbers. In POV-Ray's image each sphere must be at the pixel PinholeCamera predicts (the
// pixel whose centre ray passes nearest the sphere's centre), and every pixel must show
// what PinholeCamera's ray through its centre hits (a sphere or the background) unless
// that ray grazes a sphere; the native image must agree with POV-Ray's pixel for pixel
// but for a few grazed edge pixels. POV-Ray runs with +FP (binary PPM, read here: the
// tracer's tests do not link OpenImageIO) in a temporary directory, kept with both images
// when a check fails. Skipped when povray is not in PATH.
#include "camera.h"

#include <gtest/gtest.h>
#include <stdlib.h>  // mkdtemp

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "render.h"
#include "test_support.h"

namespace pcsg::tracer {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

double degrees(double radians) {
    return radians * 180.0 / kPi;
}
double radians(double degrees) {
    return degrees * kPi / 180.0;
}

// The angle between two vectors in degrees, accurate for small and large angles alike.
double angleBetween(const Vec3& a, const Vec3& b) {
    return degrees(std::atan2(length(cross(a, b)), dot(a, b)));
}

Camera makeCamera(Vec3 location, Vec3 lookAt, Vec3 sky, double angle) {
    Camera c;
    c.location = location;
    c.lookAt = lookAt;
    c.sky = sky;
    c.angle = angle;
    return c;
}

std::string describe(const Camera& c, int w, int h) {
    std::ostringstream s;
    s << "camera location <" << c.location.x << "," << c.location.y << "," << c.location.z
      << "> look_at <" << c.lookAt.x << "," << c.lookAt.y << "," << c.lookAt.z << "> sky <"
      << c.sky.x << "," << c.sky.y << "," << c.sky.z << "> angle " << c.angle << ", " << w << "x"
      << h;
    return s.str();
}

struct CameraCase {
    Camera cam;
    int width, height;
};

// Square, landscape, portrait and odd sizes; axis-aligned, oblique and slanted skies; narrow
// and wide angles.
std::vector<CameraCase> cameraCases() {
    return {
        {makeCamera({0, -5, 2}, {0, 0, 0}, {0, 0, 1}, 40), 64, 48},
        {makeCamera({0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 40), 64, 64},
        {makeCamera({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 60), 48, 64},
        {makeCamera({4, -6, 3}, {0, 0, 0.5}, {0, 0, 1}, 50), 80, 40},
        {makeCamera({-3, 2, -5}, {1, 0.5, 0}, {0.3, 1, 0.2}, 35), 72, 56},
        {makeCamera({0.5, -3, 1}, {0, 0, 0}, {0, 0, 1}, 100), 63, 47},
        {makeCamera({7, 1, -2}, {-1, 2, 3}, {0, 0, 2.5}, 12), 101, 33},
        {makeCamera({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 90), 640, 480},
    };
}

// The direction of the ray through image position (x, y).
Vec3 ray(const PinholeCamera& pc, double x, double y) {
    return pc.ray(x, y).dir;
}

// Where that ray meets the plane one unit in front of the camera, perpendicular to the
// viewing direction: the image plane, up to scale.
Vec3 onImagePlane(const PinholeCamera& pc, double x, double y) {
    const Vec3 d = ray(pc, x, y);
    return d / dot(d, normalize(pc.direction()));
}

void expectVecNear(const Vec3& got, const Vec3& want, double tolerance, const std::string& what) {
    EXPECT_NEAR(got.x, want.x, tolerance) << what;
    EXPECT_NEAR(got.y, want.y, tolerance) << what;
    EXPECT_NEAR(got.z, want.z, tolerance) << what;
}

TEST(PinholeCamera, CentreRayPointsAtLookAt) {
    for (const CameraCase& c : cameraCases()) {
        const PinholeCamera pc(c.cam, c.width, c.height);
        const Ray r = pc.ray(c.width / 2.0, c.height / 2.0);
        const std::string what = describe(c.cam, c.width, c.height);
        EXPECT_EQ(r.origin, c.cam.location) << what;
        expectVecNear(r.dir, normalize(c.cam.lookAt - c.cam.location), 1e-14, what);
    }
}

TEST(PinholeCamera, EdgesSpanTheHorizontalAngle) {
    for (const CameraCase& c : cameraCases()) {
        const PinholeCamera pc(c.cam, c.width, c.height);
        const double w = c.width, h = c.height;
        const std::string what = describe(c.cam, c.width, c.height);
        const Vec3 left = ray(pc, 0, h / 2), right = ray(pc, w, h / 2);
        const Vec3 centre = ray(pc, w / 2, h / 2);
        EXPECT_NEAR(angleBetween(left, right), c.cam.angle, 1e-10) << what;
        EXPECT_NEAR(angleBetween(left, centre), c.cam.angle / 2, 1e-10) << what;
        EXPECT_NEAR(angleBetween(right, centre), c.cam.angle / 2, 1e-10) << what;
    }
}

TEST(PinholeCamera, VerticalFieldFollowsFromTheAspectRatio) {
    for (const CameraCase& c : cameraCases()) {
        const PinholeCamera pc(c.cam, c.width, c.height);
        const double w = c.width, h = c.height;
        const std::string what = describe(c.cam, c.width, c.height);
        // Square pixels: the image plane's height is its width times h / w.
        const double vertical = 2 * degrees(std::atan(std::tan(radians(c.cam.angle / 2)) * h / w));
        const Vec3 top = ray(pc, w / 2, 0), bottom = ray(pc, w / 2, h);
        EXPECT_NEAR(angleBetween(top, bottom), vertical, 1e-10) << what;
        EXPECT_NEAR(angleBetween(top, ray(pc, w / 2, h / 2)), vertical / 2, 1e-10) << what;
    }
}

TEST(PinholeCamera, PlusXIsOnTheRightLookingAlongY) {
    // docs/language.md section 7: with sky <0,0,1>, looking along +y, +x is to the right.
    const PinholeCamera pc(makeCamera({0, -5, 0}, {0, 0, 0}, {0, 0, 1}, 40), 64, 48);
    const Vec3 right = ray(pc, 60, 24), left = ray(pc, 4, 24);
    const Vec3 top = ray(pc, 32, 2), bottom = ray(pc, 32, 46);
    EXPECT_GT(right.x, 0.1);
    EXPECT_NEAR(right.z, 0, 1e-15);
    EXPECT_LT(left.x, -0.1);
    EXPECT_GT(top.z, 0.1);  // sky is up
    EXPECT_NEAR(top.x, 0, 1e-15);
    EXPECT_LT(bottom.z, -0.1);
    const Vec3 topLeft = ray(pc, 0.5, 0.5);
    EXPECT_LT(topLeft.x, 0);
    EXPECT_GT(topLeft.z, 0);
    // POV-Ray's vectors after look_at and angle (camera.h): right = +x R, up = +z.
    expectVecNear(pc.right(), Vec3{64.0 / 48.0, 0, 0}, 1e-15, "right()");
    expectVecNear(pc.up(), Vec3{0, 0, 1}, 1e-15, "up()");
    expectVecNear(pc.direction(), Vec3{0, 64.0 / 48.0 / (2 * std::tan(radians(20))), 0}, 1e-14,
                  "direction()");
}

// Where the image's right and up point in the scene, for cameras whose answer is plain.
TEST(PinholeCamera, NotMirroredForOtherSkiesAndDirections) {
    struct Expected {
        Camera cam;
        Vec3 right, up;  // unit vectors towards the image's right and top
    };
    const Expected cases[] = {
        // OpenGL's view: looking down -z with y up, +x is on the right.
        {makeCamera({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 40), {1, 0, 0}, {0, 1, 0}},
        // Turned round, looking along +z with y up: +x is on the left.
        {makeCamera({0, 0, -5}, {0, 0, 0}, {0, 1, 0}, 40), {-1, 0, 0}, {0, 1, 0}},
        // Looking along -y with z up: +x is on the left.
        {makeCamera({0, 5, 0}, {0, 0, 0}, {0, 0, 1}, 40), {-1, 0, 0}, {0, 0, 1}},
        // Looking along +x with z up: +y is on the left.
        {makeCamera({-5, 0, 0}, {0, 0, 0}, {0, 0, 1}, 40), {0, -1, 0}, {0, 0, 1}},
        // Looking along +z with x up: right = direction x sky = z x x = +y.
        {makeCamera({0, 0, -5}, {0, 0, 0}, {1, 0, 0}, 40), {0, 1, 0}, {1, 0, 0}},
        // Sky upside down: the image turns by 180 degrees, it is not mirrored.
        {makeCamera({0, -5, 0}, {0, 0, 0}, {0, 0, -1}, 40), {-1, 0, 0}, {0, 0, -1}},
        // A sky not perpendicular to the view: up is the sky's part perpendicular to it.
        {makeCamera({0, -5, 0}, {0, 0, 0}, {0, 1, 1}, 40), {1, 0, 0}, {0, 0, 1}},
        // Sky along the view (POV-Ray keeps the given right, -x, and flips it by the
        // handedness): looking straight down with sky +z, +x is on the right, +y up.
        {makeCamera({0, 0, 5}, {0, 0, 0}, {0, 0, 1}, 40), {1, 0, 0}, {0, 1, 0}},
    };
    for (const Expected& e : cases) {
        const int w = 40, h = 30;
        const PinholeCamera pc(e.cam, w, h);
        const std::string what = describe(e.cam, w, h);
        expectVecNear(normalize(pc.right()), e.right, 1e-15, what + ": right()");
        expectVecNear(normalize(pc.up()), e.up, 1e-15, what + ": up()");
        // And through the rays: the centre of the right edge and of the top edge.
        const Vec3 d = normalize(e.cam.lookAt - e.cam.location);
        const Vec3 toRight = ray(pc, w, h / 2.0), toTop = ray(pc, w / 2.0, 0);
        EXPECT_NEAR(angleBetween(toRight - d * dot(toRight, d), e.right), 0, 1e-6) << what;
        EXPECT_NEAR(angleBetween(toTop - d * dot(toTop, d), e.up), 0, 1e-6) << what;
    }
    // Whatever the camera: right, up and back (towards the viewer) are a right-handed frame,
    // as the scene's axes are, and up leans towards the sky.
    for (const CameraCase& c : cameraCases()) {
        const PinholeCamera pc(c.cam, c.width, c.height);
        const std::string what = describe(c.cam, c.width, c.height);
        const Vec3 back = -normalize(pc.direction());
        expectVecNear(normalize(cross(pc.right(), pc.up())), back, 1e-14, what);
        EXPECT_GT(dot(pc.up(), c.cam.sky), 0) << what;
        EXPECT_NEAR(dot(pc.right(), c.cam.sky), 0, 1e-14) << what;
    }
}

TEST(PinholeCamera, VectorsHavePovRaysLengths) {
    for (const CameraCase& c : cameraCases()) {
        const PinholeCamera pc(c.cam, c.width, c.height);
        const std::string what = describe(c.cam, c.width, c.height);
        const double aspect = static_cast<double>(c.width) / c.height;
        EXPECT_NEAR(length(pc.right()), aspect, 1e-14) << what;
        EXPECT_NEAR(length(pc.up()), 1, 1e-14) << what;
        EXPECT_NEAR(length(pc.direction()), aspect / (2 * std::tan(radians(c.cam.angle / 2))),
                    1e-12)
            << what;
        EXPECT_NEAR(dot(pc.right(), pc.up()), 0, 1e-14) << what;
        EXPECT_NEAR(dot(pc.right(), pc.direction()), 0, 1e-13) << what;
        EXPECT_NEAR(dot(pc.up(), pc.direction()), 0, 1e-13) << what;
    }
}

TEST(PinholeCamera, DirectionsAreUnitLength) {
    for (const CameraCase& c : cameraCases()) {
        const PinholeCamera pc(c.cam, c.width, c.height);
        const std::string what = describe(c.cam, c.width, c.height);
        for (int i = 0; i <= 16; ++i)
            for (int j = 0; j <= 16; ++j) {
                const double x = c.width * i / 16.0 + (i % 3) * 0.137;
                const double y = c.height * j / 16.0 + (j % 4) * 0.291;
                const Ray r = pc.ray(x, y);
                EXPECT_NEAR(length(r.dir), 1, 1e-15) << what << " at (" << x << ", " << y << ")";
                EXPECT_EQ(r.origin, c.cam.location);
            }
    }
}

TEST(PinholeCamera, SubPixelPositionsInterpolateLinearly) {
    for (const CameraCase& c : cameraCases()) {
        const PinholeCamera pc(c.cam, c.width, c.height);
        const double w = c.width, h = c.height;
        const std::string what = describe(c.cam, c.width, c.height);
        const Vec3 origin = onImagePlane(pc, 0, 0);
        const Vec3 ex = onImagePlane(pc, 1, 0) - origin, ey = onImagePlane(pc, 0, 1) - origin;
        // Square pixels, as wide as the image plane's width over W, at right angles.
        const double pixel = 2 * std::tan(radians(c.cam.angle / 2)) / w;
        EXPECT_NEAR(length(ex), pixel, 1e-13) << what;
        EXPECT_NEAR(length(ey), pixel, 1e-13) << what;
        EXPECT_NEAR(dot(ex, ey), 0, 1e-15) << what;
        // x grows to the right, y downwards.
        EXPECT_GT(dot(ex, pc.right()), 0) << what;
        EXPECT_LT(dot(ey, pc.up()), 0) << what;
        const double positions[][2] = {{0.25, 0.75},        {0.5, 0.5},        {w - 0.5, h - 0.5},
                                       {10.125, 3.0625},    {w / 3, h * 0.71}, {w - 0.01, 0.01},
                                       {w / 2 + 0.5, h / 2}};
        for (const auto& p : positions) {
            const Vec3 want = origin + ex * p[0] + ey * p[1];
            expectVecNear(
                onImagePlane(pc, p[0], p[1]), want, 1e-12,
                what + " at (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ")");
        }
        // Pixel centres lie symmetrically about the image's centre: the first and the last
        // pixel's centres are opposite each other.
        const Vec3 centre = onImagePlane(pc, w / 2, h / 2);
        expectVecNear(onImagePlane(pc, w - 0.5, h - 0.5) - centre,
                      centre - onImagePlane(pc, 0.5, 0.5), 1e-13, what + ": pixel centres");
    }
}

// ----------------------------------------------------------------------------------------
// Against POV-Ray.

struct Ball {
    Vec3 centre;
    Vec3 colour;  // components 0 or 1, so that POV-Ray's 8-bit pixels are 0 or 255
    const char* name;
};

struct PovScene {
    Camera cam;
    int width, height;
    std::vector<Ball> balls;
    // Write `look_at` and `angle` first in the camera block (camera.h: POV-Ray 3.7 applies
    // them after all other items, wherever they are).
    bool lookAtFirst = false;
};

constexpr Vec3 kRed{1, 0, 0}, kGreen{0, 1, 0}, kBlue{0, 0, 1}, kYellow{1, 1, 0}, kMagenta{1, 0, 1},
    kCyan{0, 1, 1}, kWhite{1, 1, 1};

std::string num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

std::string vec(const Vec3& v) {
    std::string s = "<";  // (appending, not "<" + ...: GCC 12 warns about that falsely)
    s += num(v.x);
    s += ", ";
    s += num(v.y);
    s += ", ";
    s += num(v.z);
    s += ">";
    return s;
}

// A sphere about 2.5 pixels in radius at its distance from the camera.
double radiusOf(const PovScene& s, const Ball& b) {
    const double pixel = 2 * std::tan(radians(s.cam.angle / 2)) / s.width;
    return 2.5 * pixel * length(b.centre - s.cam.location);
}

std::string povSdl(const PovScene& s) {
    const double aspect = static_cast<double>(s.width) / s.height;
    std::ostringstream o;
    o << "#version 3.7;\n"
      << "global_settings { assumed_gamma 1.0 }\n"
      << "camera {\n"
      << "  perspective\n";
    if (s.lookAtFirst)
        o << "  look_at " << vec(s.cam.lookAt) << "\n  angle " << num(s.cam.angle) << "\n";
    o << "  location " << vec(s.cam.location) << "\n"
      << "  right -x*" << num(aspect) << "\n"
      << "  up y\n"
      << "  direction z\n"
      << "  sky " << vec(s.cam.sky) << "\n";
    if (!s.lookAtFirst)
        o << "  look_at " << vec(s.cam.lookAt) << "\n  angle " << num(s.cam.angle) << "\n";
    o << "}\n"
      << "background { color rgb <0, 0, 0> }\n";
    for (const Ball& b : s.balls)
        o << "sphere { " << vec(b.centre) << ", " << num(radiusOf(s, b)) << " pigment { color rgb "
          << vec(b.colour) << " } finish { ambient 1 diffuse 0 } }  // " << b.name << "\n";
    return o.str();
}

std::string pcsgText(const PovScene& s) {
    std::ostringstream o;
    o << "camera { location " << vec(s.cam.location) << "  look_at " << vec(s.cam.lookAt)
      << "  sky " << vec(s.cam.sky) << "  angle " << num(s.cam.angle) << " }\n"
      << "background <0, 0, 0>\n";
    for (size_t i = 0; i < s.balls.size(); ++i)
        o << "material m" << i << " { color " << vec(s.balls[i].colour)
          << "  ambient 1  diffuse 0 }\n";
    for (size_t i = 0; i < s.balls.size(); ++i) {
        const Ball& b = s.balls[i];
        o << (i ? " ∪\n" : "") << "paint(m" << i << ") move(" << num(b.centre.x) << ", "
          << num(b.centre.y) << ", " << num(b.centre.z) << ") uscale(" << num(radiusOf(s, b))
          << ") sphere";
    }
    o << "\n";
    return o.str();
}

struct Image {
    int width = 0, height = 0;
    std::vector<unsigned char> rgb;  // 8-bit, row-major from the top-left
    const unsigned char* at(int x, int y) const {
        return &rgb[(static_cast<size_t>(y) * width + x) * 3];
    }
};

// A binary PPM (P6, maxval 255), with the comment lines POV-Ray puts into its header.
bool readPpm(const fs::path& path, Image& image) {
    std::ifstream in(path, std::ios::binary);
    std::string magic;
    if (!(in >> magic) || magic != "P6") return false;
    int header[3];
    for (int& v : header) {
        while (in >> std::ws && in.peek() == '#') in.ignore(1 << 20, '\n');
        if (!(in >> v)) return false;
    }
    if (header[0] <= 0 || header[1] <= 0 || header[2] != 255) return false;
    in.get();  // the one whitespace character after maxval
    image.width = header[0];
    image.height = header[1];
    image.rgb.resize(static_cast<size_t>(image.width) * image.height * 3);
    in.read(reinterpret_cast<char*>(image.rgb.data()),
            static_cast<std::streamsize>(image.rgb.size()));
    return static_cast<size_t>(in.gcount()) == image.rgb.size();
}

void writePpm(const fs::path& path, const Image& image) {
    std::ofstream out(path, std::ios::binary);
    out << "P6\n" << image.width << " " << image.height << "\n255\n";
    out.write(reinterpret_cast<const char*>(image.rgb.data()),
              static_cast<std::streamsize>(image.rgb.size()));
}

// Linear to 8-bit sRGB, as POV-Ray 3.7 writes 8-bit files with assumed_gamma 1.0.
unsigned char srgb8(double linear) {
    const double v = std::clamp(linear, 0.0, 1.0);
    const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
    return static_cast<unsigned char>(std::lround(e * 255));
}

bool isColour(const unsigned char* p, const Vec3& c) {
    for (int k = 0; k < 3; ++k)
        if (std::abs(p[k] - 255 * c[k]) > 2) return false;
    return true;
}

bool havePovray() {
    return std::system("command -v povray > /dev/null 2>&1") == 0;
}

struct PixelPos {
    int x = -1, y = -1;
};

// The pixel whose centre ray passes nearest the point.
PixelPos nearestPixel(const PinholeCamera& pc, int w, int h, const Vec3& point) {
    PixelPos best;
    double bestDistance = 1e300;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Ray r = pc.ray(x + 0.5, y + 0.5);
            const Vec3 v = point - r.origin;
            if (dot(v, r.dir) <= 0) continue;
            const double distance = length(cross(v, r.dir));
            if (distance < bestDistance) bestDistance = distance, best = {x, y};
        }
    return best;
}

// A fresh temporary directory, removed at the end unless the test has failed by then.
class TempDir {
  public:
    TempDir() {
        std::string pattern = (fs::temp_directory_path() / "pcsg_camera_test_XXXXXX").string();
        if (mkdtemp(pattern.data())) path_ = pattern;
    }
    ~TempDir() {
        if (path_.empty()) return;
        if (::testing::Test::HasFailure()) {
            std::fprintf(stderr, "scenes and images kept in %s\n", path_.c_str());
            return;
        }
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const fs::path& path() const { return path_; }

  private:
    fs::path path_;
};

// Renders the scene with POV-Ray and natively and checks both images; see the top of the
// file.
void checkAgainstPovray(const PovScene& s) {
    const int w = s.width, h = s.height;
    const std::string what = describe(s.cam, w, h);
    const PinholeCamera pc(s.cam, w, h);

    // The scene must be laid out so that each sphere is whole, inside the image and apart
    // from the others: otherwise a wrong camera could pass.
    std::vector<PixelPos> predicted;
    for (const Ball& b : s.balls) {
        predicted.push_back(nearestPixel(pc, w, h, b.centre));
        const PixelPos& p = predicted.back();
        ASSERT_TRUE(p.x >= 4 && p.x < w - 4 && p.y >= 4 && p.y < h - 4)
            << what << ": PinholeCamera puts the " << b.name << " sphere at pixel (" << p.x << ", "
            << p.y << "), at the image's edge: the camera moved it, or the scene needs "
            << "another layout";
    }
    for (size_t i = 0; i < predicted.size(); ++i)
        for (size_t j = 0; j < i; ++j)
            ASSERT_GE(std::max(std::abs(predicted[i].x - predicted[j].x),
                               std::abs(predicted[i].y - predicted[j].y)),
                      7)
                << what << ": the " << s.balls[i].name << " and " << s.balls[j].name
                << " spheres are within 7 pixels of each other: the camera moved them, or the "
                << "scene needs another layout";

    TempDir dir;
    ASSERT_FALSE(dir.path().empty()) << "cannot make a temporary directory";
    {
        std::ofstream out(dir.path() / "scene.pov");
        out << povSdl(s);
        std::ofstream pcsg(dir.path() / "scene.pcsg");
        pcsg << pcsgText(s);
    }
    const std::string cmd = "cd '" + dir.path().string() +
                            "' && povray +Iscene.pov +Oscene.ppm +FP +W" + std::to_string(w) +
                            " +H" + std::to_string(h) +
                            " -D -V +WT1 -A < /dev/null > povray.log 2>&1";
    const int status = std::system(cmd.c_str());
    std::ifstream logIn(dir.path() / "povray.log");
    const std::string log((std::istreambuf_iterator<char>(logIn)), {});
    ASSERT_EQ(status, 0) << "povray failed on " << dir.path() / "scene.pov"
                         << ":\n"
                         << log;
    EXPECT_EQ(log.find("Warning:"), std::string::npos) << log;
    Image pov;
    ASSERT_TRUE(readPpm(dir.path() / "scene.ppm", pov)) << "cannot read POV-Ray's image";
    ASSERT_EQ(pov.width, w);
    ASSERT_EQ(pov.height, h);

    // Each sphere where PinholeCamera puts it: at the pixel whose ray passes nearest its
    // centre.
    for (size_t i = 0; i < s.balls.size(); ++i) {
        const Ball& b = s.balls[i];
        const PixelPos p = predicted[i];
        const unsigned char* got = pov.at(p.x, p.y);
        EXPECT_TRUE(isColour(got, b.colour))
            << what << ": the " << b.name << " sphere at " << vec(b.centre)
            << " should be at pixel (" << p.x << ", " << p.y << "), but POV-Ray's pixel there is ("
            << int(got[0]) << ", " << int(got[1]) << ", " << int(got[2]) << ")";
    }
    // And whole: every pixel whose centre ray, as PinholeCamera casts it, hits a sphere has
    // that sphere's colour in POV-Ray's image, every other pixel is black; only a ray that
    // grazes a sphere may go either way.
    std::vector<int> covered(s.balls.size());
    int wrong = 0;
    std::ostringstream wrongAt;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Ray r = pc.ray(x + 0.5, y + 0.5);
            int hit = -1;
            double nearest = 1e300;
            bool grazing = false;
            for (size_t i = 0; i < s.balls.size(); ++i) {
                const Vec3 v = s.balls[i].centre - r.origin;
                const double radius = radiusOf(s, s.balls[i]);
                const double along = dot(v, r.dir), off = length(cross(v, r.dir));
                if (std::abs(off - radius) < 1e-9 * radius) grazing = true;
                if (off >= radius || along <= 0) continue;
                const double entry = along - std::sqrt(radius * radius - off * off);
                if (entry < nearest) nearest = entry, hit = static_cast<int>(i);
            }
            if (hit >= 0) ++covered[hit];
            const Vec3 want = hit < 0 ? Vec3{0, 0, 0} : s.balls[hit].colour;
            const unsigned char* got = pov.at(x, y);
            if (isColour(got, want) || grazing) continue;
            if (++wrong <= 10)
                wrongAt << " (" << x << ", " << y << "): expected "
                        << (hit < 0 ? "background" : s.balls[hit].name) << ", POV-Ray has ("
                        << int(got[0]) << ", " << int(got[1]) << ", " << int(got[2]) << ")";
        }
    EXPECT_EQ(wrong, 0) << what << ": POV-Ray's image differs from PinholeCamera's prediction at "
                        << wrong << " pixels:" << wrongAt.str();
    for (size_t i = 0; i < s.balls.size(); ++i)
        EXPECT_GE(covered[i], 9) << what << ": the " << s.balls[i].name << " sphere covers only "
                                 << covered[i] << " pixels, too few for this test";

    // The native image, pixel for pixel.
    auto compiled = testing::compile(pcsgText(s));
    ASSERT_TRUE(compiled->graph);
    RenderOptions o;
    o.width = w;
    o.height = h;
    o.threads = 2;
    const RenderResult r = render(*compiled->graph, o);
    ASSERT_EQ(r.rgb.size(), static_cast<size_t>(w) * h * 3);
    Image native{w, h, std::vector<unsigned char>(r.rgb.size())};
    for (size_t k = 0; k < r.rgb.size(); ++k) native.rgb[k] = srgb8(r.rgb[k]);
    // A pixel may differ only where its centre ray grazes a sphere: on an edge, next to a
    // pixel of another colour in POV-Ray's image.
    auto onEdge = [&](int x, int y) {
        const int dx[] = {1, -1, 0, 0}, dy[] = {0, 0, 1, -1};
        for (int k = 0; k < 4; ++k) {
            const int nx = x + dx[k], ny = y + dy[k];
            if (nx >= 0 && nx < w && ny >= 0 && ny < h &&
                !std::equal(pov.at(x, y), pov.at(x, y) + 3, pov.at(nx, ny)))
                return true;
        }
        return false;
    };
    int differing = 0, inner = 0;
    std::ostringstream where;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const unsigned char *a = pov.at(x, y), *n = native.at(x, y);
            int d = 0;
            for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int(a[k]) - int(n[k])));
            if (d <= 2) continue;
            ++differing;
            if (!onEdge(x, y)) ++inner;
            if (differing <= 10)
                where << " (" << x << ", " << y << "): POV-Ray (" << int(a[0]) << ", " << int(a[1])
                      << ", " << int(a[2]) << ") native (" << int(n[0]) << ", " << int(n[1]) << ", "
                      << int(n[2]) << ")";
        }
    EXPECT_LE(differing, 3) << what << ": " << differing << " pixels differ:" << where.str();
    EXPECT_EQ(inner, 0) << what << ": pixels off an edge differ:" << where.str();

    if (::testing::Test::HasFailure()) writePpm(dir.path() / "native.ppm", native);
}

#define SKIP_WITHOUT_POVRAY() \
    if (!havePovray()) GTEST_SKIP() << "povray is not in PATH (apt-get install povray)"

TEST(PovrayCamera, PlusXIsOnTheRightLookingAlongY) {
    SKIP_WITHOUT_POVRAY();
    checkAgainstPovray({makeCamera({0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 40),
                        64,
                        48,
                        {{{2, 0, 0}, kRed, "+x"},
                         {{0, 0, 1.8}, kGreen, "+z"},
                         {{0, 4, 0}, kBlue, "+y (behind look_at)"},
                         {{-2.2, 1, -1.5}, kYellow, "off-axis (-x, +y, -z)"},
                         {{1, -5, 0.8}, kMagenta, "near (+x, -y, +z)"}}});
}

TEST(PovrayCamera, LookingDownZWithSkyYPortrait) {
    SKIP_WITHOUT_POVRAY();
    checkAgainstPovray({makeCamera({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 60),
                        48,
                        64,
                        {{{3, 0, 0}, kRed, "+x"},
                         {{0, 3, 0}, kGreen, "+y"},
                         {{1, -1.5, 4}, kBlue, "+z (near)"},
                         {{-2.5, -5, 1}, kYellow, "off-axis (-x, -y)"},
                         {{-3, 4, -2}, kCyan, "off-axis (-x, +y, -z)"}}});
}

TEST(PovrayCamera, ObliqueWideImage) {
    SKIP_WITHOUT_POVRAY();
    checkAgainstPovray({makeCamera({4, -6, 3}, {0, 0, 0.5}, {0, 0, 1}, 50),
                        80,
                        40,
                        {{{1.8, 0, 0}, kRed, "+x"},
                         {{0, 1.8, 0}, kGreen, "+y"},
                         {{0, 0, 1.8}, kBlue, "+z"},
                         {{-1.5, -1, 0.2}, kYellow, "off-axis (-x, -y)"},
                         {{0, 0, 0.5}, kWhite, "look_at"}}});
}

TEST(PovrayCamera, SlantedSky) {
    SKIP_WITHOUT_POVRAY();
    checkAgainstPovray({makeCamera({-3, 2, -5}, {1, 0.5, 0}, {0.3, 1, 0.2}, 35),
                        72,
                        56,
                        {{{2, 0.5, 0}, kRed, "+x of look_at"},
                         {{1, 1.4, 0}, kGreen, "+y of look_at"},
                         {{1, 0.5, 1.2}, kBlue, "+z of look_at"},
                         {{0.2, -0.3, 0.4}, kYellow, "off-axis"},
                         {{1, 0.5, 0}, kWhite, "look_at"}}});
}

TEST(PovrayCamera, WideAngleOffAxisCorners) {
    SKIP_WITHOUT_POVRAY();
    checkAgainstPovray({makeCamera({0.5, -3, 1}, {0, 0, 0}, {0, 0, 1}, 100),
                        63,
                        47,
                        {{{2.4, 0, 1.2}, kRed, "top right"},
                         {{-2.6, -0.5, 1.3}, kGreen, "top left"},
                         {{-1.8, 0.5, -1.5}, kBlue, "bottom left"},
                         {{3, 1, -1.6}, kYellow, "bottom right"},
                         {{0, 2, 0.5}, kMagenta, "far, +y"}}});
}

// camera.h: look_at and angle may stand anywhere in the block.
TEST(PovrayCamera, LookAtAndAngleFirstInTheBlock) {
    SKIP_WITHOUT_POVRAY();
    PovScene s{makeCamera({-4, -5, 2.5}, {0.5, 0, 0.3}, {0, 0, 1}, 30),
               72,
               40,
               {{{2, 0, 0}, kRed, "+x"},
                {{0, 1.5, 0}, kGreen, "+y"},
                {{0, 0, 0.9}, kBlue, "+z"},
                {{-1, 0.5, -0.1}, kYellow, "off-axis"}}};
    s.lookAtFirst = true;
    checkAgainstPovray(s);
}

}  // namespace
}  // namespace pcsg::tracer
