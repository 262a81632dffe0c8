// Tests of the POV-Ray writer: the text for each primitive, the structure (materials,
// bounds, regrouped unions), and POV-Ray itself: every primitive's silhouette as POV-Ray
// renders it must match the solid of docs/language.md section 5 seen through the camera of
// section 7, computed here independently by marching the same rays.
#include "pov_writer.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <numbers>
#include <regex>
#include <sstream>

#include "eval.h"
#include "pov_test_util.h"
#include "test_graphs.h"

namespace pcsg {
namespace {

using namespace testgraphs;
using P = PrimitiveKind;

std::string exportText(const Graph& g, const PovOptions& opt = {}) {
    const ExpandedTree t = expand(g);
    std::ostringstream os;
    writePov(g, t, os, opt);
    return os.str();
}

size_t occurrences(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1))
        ++n;
    return n;
}

// A scene of one primitive under one transformation.
Graph single(P kind, NodeId (*wrap)(Graph&, NodeId), std::vector<double> values = {}) {
    Graph g;
    defaultScene(g);
    g.axiom = wrap(g, primitive(g, kind, std::move(values)));
    return g;
}
NodeId moveScale(Graph& g, NodeId n) {
    return transform(g, TransformOp::Move, {1, 2, 3}, transform(g, TransformOp::UScale, {2}, n));
}
NodeId rotZ90(Graph& g, NodeId n) {
    return transform(g, TransformOp::RotZ, {90}, n);
}

TEST(PovWriter, HeaderHasVersionSettingsCameraLightsBackground) {
    Graph g = single(P::Sphere, moveScale);
    g.scene.background = {0.5, 0.25, 1};
    g.scene.camera.location = {4, -6, 3};
    g.scene.lights = {Light{{10, -20, 30}, {1, 1, 1}}, Light{{-5, 0, 8}, {0.5, 0.5, 0.5}}};
    PovOptions opt;
    opt.width = 320;
    opt.height = 240;
    const std::string s = exportText(g, opt);
    EXPECT_NE(s.find("#version 3.7;"), std::string::npos);
    EXPECT_NE(s.find("global_settings { assumed_gamma 1.0 max_trace_level 5 }"), std::string::npos);
    EXPECT_NE(s.find("location <4,-6,3>"), std::string::npos) << s;
    EXPECT_NE(s.find("right -x*1.3333333333333333"), std::string::npos) << s;
    EXPECT_NE(s.find("angle 40"), std::string::npos);
    EXPECT_NE(s.find("sky <0,0,1>"), std::string::npos);
    // The block tracer/camera.h reproduces: up y and direction z as given, sky before
    // look_at.
    EXPECT_NE(s.find("  up y\n  direction z\n"), std::string::npos) << s;
    EXPECT_LT(s.find("sky <"), s.find("look_at"));
    EXPECT_NE(s.find("light_source { <10,-20,30> color rgb <1,1,1> }"), std::string::npos) << s;
    EXPECT_NE(s.find("light_source { <-5,0,8> color rgb <0.5,0.5,0.5> }"), std::string::npos);
    EXPECT_NE(s.find("background { color rgb <0.5,0.25,1> }"), std::string::npos);
}

TEST(PovWriter, EachMaterialIsDeclaredOnceAsATexture) {
    Graph g;
    defaultScene(g);
    Material bark;
    bark.name = "bark";
    bark.color = {0.35, 0.22, 0.1};
    bark.ambient = 0.2;
    bark.diffuse = 0.7;
    bark.phong = 0.3;
    bark.phongSize = 30;
    bark.reflection = 0.1;
    g.materials.push_back(bark);
    std::vector<NodeId> parts;
    for (int i = 0; i < 5; ++i)
        parts.push_back(paint(
            g, 1, transform(g, TransformOp::Move, {double(i), 0, 0}, primitive(g, P::Sphere))));
    parts.push_back(primitive(g, P::Cube));
    g.axiom = g.addOperator(CsgOp::Union, parts);
    const std::string s = exportText(g);
    EXPECT_EQ(occurrences(s, "#declare M1 = texture"), 1u);
    EXPECT_NE(s.find("#declare M0 = texture { pigment { color rgb <1,1,1> } finish { ambient 0.1 "
                     "diffuse 0.6 phong 0 phong_size 40 reflection 0 } }"),
              std::string::npos)
        << s;
    EXPECT_NE(s.find("#declare M1 = texture { pigment { color rgb <0.35,0.22,0.1> } finish { "
                     "ambient 0.2 diffuse 0.7 phong 0.3 phong_size 30 reflection 0.1 } }  // bark"),
              std::string::npos)
        << s;
    EXPECT_EQ(occurrences(s, "texture{M1}"), 5u);
    EXPECT_EQ(occurrences(s, "texture{M0}"), 1u);
}

// Section 10's finish items are written where they differ from POV-Ray's defaults; a
// material with an interior makes every material a POV-Ray `material` with an interior
// (ior 1 where the scene gives none), so that each use of one is an object with its own
// interior, as the tracer's interiors are.
TEST(PovWriter, FinishItemsAndInteriors) {
    Graph g;
    defaultScene(g);
    Material glass;
    glass.name = "glass";
    glass.brilliance = 2;
    glass.specular = 0.5;
    glass.roughness = 0.01;
    glass.metallic = 0.25;
    glass.reflectionRange = true;
    glass.reflectionMin = 0.05;
    glass.reflection = 0.9;
    glass.fresnel = true;
    glass.reflectMetallic = 1;
    glass.conserveEnergy = true;
    glass.interior = true;
    glass.ior = 1.5;
    g.materials.push_back(glass);
    g.axiom =
        g.addOperator(CsgOp::Union, {paint(g, 1, primitive(g, P::Sphere)), primitive(g, P::Cube)});
    const std::string s = exportText(g);
    EXPECT_NE(
        s.find(
            "#declare M0 = material { texture { pigment { color rgb <1,1,1> } finish { "
            "ambient 0.1 diffuse 0.6 phong 0 phong_size 40 reflection 0 } } interior { ior 1 } }"),
        std::string::npos)
        << s;
    EXPECT_NE(s.find("#declare M1 = material { texture { pigment { color rgb <1,1,1> } finish { "
                     "ambient 0.1 diffuse 0.6 brilliance 2 phong 0 phong_size 40 specular 0.5 "
                     "roughness 0.01 metallic 0.25 reflection { 0.05, 0.9 fresnel on metallic 1 } "
                     "conserve_energy } } interior { ior 1.5 } }  // glass"),
              std::string::npos)
        << s;
    EXPECT_EQ(occurrences(s, "material{M1}"), 1u);
    EXPECT_EQ(occurrences(s, "material{M0}"), 1u);
    EXPECT_EQ(occurrences(s, "texture{M"), 0u);
}

// Transparency: a colour with filter and transmit is written as rgbft, the interior's fade
// items where they are not POV-Ray's defaults, and the settings' max_trace_level and
// adc_bailout in global_settings.
TEST(PovWriter, FilterTransmitFadeAndTraceLevel) {
    Graph g;
    defaultScene(g);
    g.scene.settings.maxTraceLevel = 9;
    g.scene.settings.adcBailout = 0.01;
    Material glass;
    glass.color = {0.5, 1, 0.25};
    glass.filter = 0.75;
    glass.transmit = 0.125;
    glass.interior = true;
    glass.ior = 1.33;
    glass.fadeDistance = 2;
    glass.fadePower = 1001;
    glass.fadeColour = {0.5, 0, 0};
    g.materials.push_back(glass);
    g.axiom = paint(g, 1, primitive(g, P::Sphere));
    const std::string s = exportText(g);
    EXPECT_NE(s.find("global_settings { assumed_gamma 1.0 max_trace_level 9 adc_bailout 0.01 }"),
              std::string::npos)
        << s;
    EXPECT_NE(s.find("pigment { color rgbft <0.5,1,0.25,0.75,0.125> }"), std::string::npos) << s;
    EXPECT_NE(s.find("interior { ior 1.33 fade_distance 2 fade_power 1001 fade_color rgb "
                     "<0.5,0,0> } }"),
              std::string::npos)
        << s;
}

// A material that lets light through, without an interior, makes every material a POV-Ray
// `material` with an interior too: without, POV-Ray would give all objects the root's one
// interior.
TEST(PovWriter, TransparencyGivesEveryMaterialAnInterior) {
    Graph g;
    defaultScene(g);
    Material veil;
    veil.transmit = 0.5;
    g.materials.push_back(veil);
    g.axiom =
        g.addOperator(CsgOp::Union, {paint(g, 1, primitive(g, P::Sphere)), primitive(g, P::Cube)});
    const std::string s = exportText(g);
    EXPECT_EQ(occurrences(s, "interior { ior 1 } }"), 2u) << s;
    EXPECT_EQ(occurrences(s, "material{M1}"), 1u);
    EXPECT_EQ(occurrences(s, "material{M0}"), 1u);
    EXPECT_EQ(occurrences(s, "texture{M"), 0u);
}

// Below an intersection or difference, a union is written as POV-Ray's merge when some
// material lets light through: the tracer's span lists have no surfaces inside the union
// there, POV-Ray's union keeps them, and light passing through would show them. At the
// top, the tracer's first hits see them too, and a union stays a union.
TEST(PovWriter, AUnionInACutIsAMergeWhenLightPasses) {
    for (const bool transparent : {false, true}) {
        Graph g;
        defaultScene(g);
        Material glass;
        glass.transmit = transparent ? 0.5 : 0;
        g.materials.push_back(glass);
        const NodeId u =
            g.addOperator(CsgOp::Union, {primitive(g, P::Sphere), primitive(g, P::Cube)});
        const NodeId cut =
            g.addOperator(CsgOp::Difference, {paint(g, 1, u), primitive(g, P::Cylinder)});
        g.axiom = g.addOperator(CsgOp::Union, {cut, primitive(g, P::Cone)});
        const std::string s = exportText(g);
        EXPECT_EQ(occurrences(s, "merge {"), transparent ? 1u : 0u) << s;
        EXPECT_EQ(occurrences(s, "union {"), transparent ? 1u : 2u) << s;
    }
}

// A paint node's material is one texture where the paint stands (docs/language.md
// section 10): on the union it paints, not copied onto each primitive. An inner paint is
// a texture of its own, which POV-Ray keeps (inner textures override outer), and the root
// carries the default material for what no paint reaches.
TEST(PovWriter, APaintIsOneTextureWhereThePaintStands) {
    Graph g;
    defaultScene(g);
    g.materials.push_back(Material{.name = "a"});
    g.materials.push_back(Material{.name = "b"});
    std::vector<NodeId> inner;
    for (int i = 0; i < 40; ++i)  // more than maxUnionChildren: the union is regrouped
        inner.push_back(
            transform(g, TransformOp::Move, {double(i), 0, 0}, primitive(g, P::Sphere)));
    inner.push_back(paint(g, 2, primitive(g, P::Cone)));
    const NodeId painted = paint(g, 1, g.addOperator(CsgOp::Union, inner));
    g.axiom = g.addOperator(CsgOp::Union, {painted, primitive(g, P::Cylinder)});
    const std::string s = exportText(g);
    EXPECT_EQ(occurrences(s, "texture{M1}"), 1u) << s;
    EXPECT_EQ(occurrences(s, "texture{M2}"), 1u) << s;
    EXPECT_EQ(occurrences(s, "texture{M0}"), 1u) << s;
    EXPECT_NE(s.find("cone{<0,0,0>,1,<0,0,1>,0 texture{M2}"), std::string::npos) << s;
    EXPECT_EQ(occurrences(s, "sphere{<0,0,0>,1 matrix"), 40u) << s;
    // The root union closes with the default texture, after every primitive.
    EXPECT_GT(s.rfind(" texture{M0}"), s.rfind("cylinder{")) << s;
    EXPECT_GT(s.rfind(" texture{M1}"), s.rfind("sphere{")) << s;
}

TEST(PovWriter, PrimitivesInPovRaysOwnFormWithTheTransposedMatrix) {
    // move(1,2,3) uscale(2): L = 2I, t = (1,2,3).
    const std::string m = " matrix<2,0,0,0,2,0,0,0,2,1,2,3>}";
    EXPECT_NE(exportText(single(P::Sphere, moveScale)).find("sphere{<0,0,0>,1 texture{M0}" + m),
              std::string::npos);
    EXPECT_NE(exportText(single(P::Cube, moveScale)).find("box{<-1,-1,-1>,<1,1,1> texture{M0}" + m),
              std::string::npos);
    EXPECT_NE(exportText(single(P::Cylinder, moveScale))
                  .find("cylinder{<0,0,0>,<0,0,1>,1 texture{M0}" + m),
              std::string::npos);
    EXPECT_NE(
        exportText(single(P::Cone, moveScale)).find("cone{<0,0,0>,1,<0,0,1>,0 texture{M0}" + m),
        std::string::npos);
    // A plane goes out in world coordinates (POV-Ray mishandles a plane's `matrix` in
    // CSG: docs/fuzz.md): z <= 0 moved up by 3 and scaled about its own origin.
    EXPECT_NE(exportText(single(P::Plane, moveScale)).find("plane{<0,0,1>,3 texture{M0}}"),
              std::string::npos);
    const std::string tetra = exportText(single(P::Tetrahedron, moveScale));
    EXPECT_NE(tetra.find("object{PcsgTetrahedron texture{M0}" + m), std::string::npos);
    EXPECT_EQ(occurrences(tetra, "#declare PcsgTetrahedron = intersection"), 1u);
    EXPECT_EQ(occurrences(tetra, "  plane { "), 4u);
    // rotz(90) takes x to y: L = [[0,-1,0],[1,0,0],[0,0,1]]; POV-Ray's rows are L's columns.
    EXPECT_NE(exportText(single(P::Sphere, rotZ90)).find("matrix<0,1,0,-1,0,0,0,0,1,0,0,0>"),
              std::string::npos);
    // The torus about z: POV-Ray's lies about y, so the matrix is L times (y -> z).
    const std::string torus = exportText(single(P::Torus, moveScale, {1.5, 0.25}));
    EXPECT_NE(torus.find("torus{1.5,0.25 texture{M0} matrix<2,0,0,0,0,2,0,-2,0,1,2,3>}"),
              std::string::npos)
        << torus;
    // Triangles: the corners in world coordinates.
    const std::string tri = exportText(single(P::Tri1, moveScale));
    EXPECT_NE(tri.find("triangle{<1,2,3>,<3,2,3>,<1,4,3> texture{M0}}"), std::string::npos) << tri;
    const std::string tri2 = exportText(single(P::Tri2, moveScale));
    EXPECT_NE(tri2.find("triangle{<1,2,3>,<-1,2,3>,<1,0,3> texture{M0}}"), std::string::npos)
        << tri2;
    const std::string tri3 =
        exportText(single(P::Triangle, moveScale, {0, 0, 0, 1, 0, 0, 0, 0, 1}));
    EXPECT_NE(tri3.find("triangle{<1,2,3>,<3,2,3>,<1,2,5> texture{M0}}"), std::string::npos)
        << tri3;
}

TEST(PovWriter, DegenerateTrianglesAndEmptyAreLeftOut) {
    Graph g;
    defaultScene(g);
    g.axiom = g.addOperator(CsgOp::Union, {primitive(g, P::Triangle, {0, 0, 0, 1, 1, 1, 2, 2, 2}),
                                           primitive(g, P::Empty), primitive(g, P::Tri1)});
    const ExpandedTree t = expand(g);
    std::ostringstream os;
    const PovWriteStats st = writePov(g, t, os);
    EXPECT_EQ(st.objects, 1u);
    EXPECT_EQ(st.skipped, 1u);
    EXPECT_EQ(occurrences(os.str(), "triangle{"), 1u);
    EXPECT_EQ(st.bytes, os.str().size());
}

TEST(PovWriter, IntersectionsAndDifferencesAreBounded) {
    // (plane ∩ sphere) ∪ (cube \ sphere), moved.
    Graph g;
    defaultScene(g);
    const NodeId a =
        g.addOperator(CsgOp::Intersection, {primitive(g, P::Plane), primitive(g, P::Sphere)});
    const NodeId b = g.addOperator(
        CsgOp::Difference, {primitive(g, P::Cube),
                            transform(g, TransformOp::Move, {0, 0, 1}, primitive(g, P::Sphere))});
    g.axiom =
        transform(g, TransformOp::Move, {10, 0, 0},
                  g.addOperator(CsgOp::Union, {a, transform(g, TransformOp::Move, {0, 5, 0}, b)}));
    const std::string s = exportText(g);
    EXPECT_EQ(occurrences(s, "intersection {"), 1u);
    EXPECT_EQ(occurrences(s, "difference {"), 1u);
    EXPECT_EQ(occurrences(s, "union {"), 1u);
    // Two boxes: the intersection's is the lower half of the sphere's, the difference's
    // the cube's. The union has none: POV-Ray bounds unions of bounded objects itself.
    const std::regex box(
        R"(bounded_by\{box\{<([-0-9.e]+),([-0-9.e]+),([-0-9.e]+)>,<([-0-9.e]+),([-0-9.e]+),([-0-9.e]+)>\}\})");
    std::vector<std::array<double, 6>> boxes;
    for (auto it = std::sregex_iterator(s.begin(), s.end(), box); it != std::sregex_iterator();
         ++it) {
        std::array<double, 6> v{};
        for (int i = 0; i < 6; ++i) v[i] = std::stod((*it)[i + 1]);
        boxes.push_back(v);
    }
    ASSERT_EQ(boxes.size(), 2u) << s;
    const std::array<double, 6> expect[2] = {{9, -1, -1, 11, 1, 0}, {9, 4, -1, 11, 6, 1}};
    for (int k = 0; k < 2; ++k)
        for (int i = 0; i < 6; ++i) EXPECT_NEAR(boxes[k][i], expect[k][i], 1e-4) << k << " " << i;
}

TEST(PovWriter, BigUnionsAreRegroupedIntoABalancedNest) {
    // A 1000-operand union of spheres along a line.
    Graph g;
    defaultScene(g);
    std::vector<NodeId> parts;
    for (int i = 0; i < 1000; ++i)
        parts.push_back(
            transform(g, TransformOp::Move, {double(i) * 3, 0, 0}, primitive(g, P::Sphere)));
    g.axiom = g.addOperator(CsgOp::Union, parts);
    const ExpandedTree t = expand(g);
    std::ostringstream os;
    // Bounded unions here only to see the groups' extents.
    PovOptions opt;
    opt.maxUnionChildren = 16;
    opt.boundUnions = true;
    const PovWriteStats st = writePov(g, t, os, opt);
    const std::string s = os.str();
    EXPECT_EQ(st.objects, 1000u);
    EXPECT_EQ(occurrences(s, "sphere{"), 1000u);
    // Count the operands of each union by walking the braces.
    std::vector<int> operands;  // per open union
    std::vector<bool> isUnion;
    int maxOperands = 0, unions = 0;
    std::istringstream in(s.substr(s.find("union {")));
    std::string line;
    while (std::getline(in, line)) {
        const bool opens = line.find("union {") != std::string::npos;
        const bool object = line.find("sphere{") != std::string::npos;
        const bool closes = line.find(" }") != std::string::npos && !object && !opens;
        if ((opens || object) && !operands.empty()) ++operands.back();
        if (opens) {
            operands.push_back(0);
            ++unions;
        }
        if (closes) {
            ASSERT_FALSE(operands.empty());
            maxOperands = std::max(maxOperands, operands.back());
            EXPECT_GE(operands.back(), 2);
            operands.pop_back();
        }
    }
    EXPECT_TRUE(operands.empty());
    EXPECT_LE(maxOperands, 16);
    EXPECT_GE(unions, 1000 / 16);
    EXPECT_EQ(occurrences(s, "bounded_by"), static_cast<size_t>(unions));
    // Spatial grouping: each bounding box of a leaf group spans few spheres, so the sum of
    // the box widths stays near the line's length times the nesting depth, far below
    // what random grouping would give (about 3000 per union).
    const std::regex box(R"(bounded_by\{box\{<([-0-9.e]+),[^>]*>,<([-0-9.e]+),)");
    double widths = 0;
    for (auto it = std::sregex_iterator(s.begin(), s.end(), box); it != std::sregex_iterator();
         ++it)
        widths += std::stod((*it)[2]) - std::stod((*it)[1]);
    EXPECT_LT(widths, 3000.0 * 4);
}

TEST(PovWriter, LongUnionChainsAreFlattenedBeforePovRaysBraceLimit) {
    // ((((cube ∪ sphere) ∪ sphere) ∪ sphere) ...) 30,000 deep: POV-Ray's parser crashes
    // at about 19,000 nested braces.
    Graph g;
    defaultScene(g);
    NodeId n = primitive(g, P::Cube);
    for (int i = 0; i < 30000; ++i)
        n = g.addOperator(CsgOp::Union, {n, transform(g, TransformOp::Move, {0.001 * i, 0, 0},
                                                      primitive(g, P::Sphere))});
    g.axiom = n;
    const std::string s = exportText(g);
    int depth = 0, maxDepth = 0;
    for (char c : s) {
        depth += c == '{';
        depth -= c == '}';
        maxDepth = std::max(maxDepth, depth);
    }
    EXPECT_EQ(depth, 0);
    EXPECT_LT(maxDepth, 300);
    EXPECT_EQ(occurrences(s, "sphere{"), 30000u);
    EXPECT_EQ(occurrences(s, "box{"), 1u);
}

TEST(PovWriter, StreamsWithoutHoldingTheText) {
    // Sierpinski order 8 with spheres: 65,536 primitives into a stream that only counts.
    struct CountingBuf : std::streambuf {
        uint64_t n = 0;
        uint64_t lines = 0;
        std::streamsize xsputn(const char* s, std::streamsize k) override {
            n += static_cast<uint64_t>(k);
            for (std::streamsize i = 0; i < k; ++i) lines += s[i] == '\n';
            return k;
        }
        int overflow(int c) override {
            ++n;
            return c;
        }
    } buf;
    std::ostream os(&buf);
    const Graph g = sierpinski(8, P::Sphere);
    const ExpandedTree t = expand(g);
    const PovWriteStats st = writePov(g, t, os);
    EXPECT_EQ(st.objects, 1u << 16);
    EXPECT_EQ(st.bytes, buf.n);
    EXPECT_GT(buf.lines, (1u << 16));
}

// ---------------------------------------------------------------------------------------
// POV-Ray renders what docs/language.md describes.

// The solid of a primitive in its own coordinates (docs/language.md section 5).
bool insidePrimitive(P kind, const Vec3& p, const std::vector<double>& a) {
    switch (kind) {
        case P::Sphere:
            return dot(p, p) <= 1;
        case P::Cube:
            return std::fabs(p.x) <= 1 && std::fabs(p.y) <= 1 && std::fabs(p.z) <= 1;
        case P::Cylinder:
            return p.x * p.x + p.y * p.y <= 1 && p.z >= 0 && p.z <= 1;
        case P::Cone:
            return p.z >= 0 && p.z <= 1 && std::sqrt(p.x * p.x + p.y * p.y) <= 1 - p.z;
        case P::Tetrahedron:
            for (const Vec3 v : {Vec3{1, 1, 1}, Vec3{-1, -1, 1}, Vec3{1, -1, -1}, Vec3{-1, 1, -1}})
                if (-dot(v, p) > 1) return false;
            return true;
        case P::Torus: {
            const double q = std::sqrt(p.x * p.x + p.y * p.y) - a[0];
            return q * q + p.z * p.z <= a[1] * a[1];
        }
        case P::Plane:
            return p.z <= 0;
        default:
            return false;
    }
}

struct Pinhole {
    Vec3 eye, forward, right, up;
    double tanX, tanY;
    Pinhole(const Camera& c, int w, int h) {
        eye = c.location;
        forward = normalize(c.lookAt - c.location);
        right = normalize(cross(forward, c.sky));
        up = cross(right, forward);
        tanX = std::tan(c.angle * std::numbers::pi / 360);
        tanY = tanX * h / w;
    }
    Vec3 ray(int i, int j, int w, int h) const {
        const double sx = ((i + 0.5) / w - 0.5) * 2, sy = (0.5 - (j + 0.5) / h) * 2;
        return normalize(forward + right * (sx * tanX) + up * (sy * tanY));
    }
};

struct SilhouetteCase {
    std::string name;
    std::function<NodeId(Graph&)> build;                // the scene's axiom
    std::function<bool(const Vec3&)> inside;            // its solid, for marching
    std::function<bool(const Vec3&, const Vec3&)> hit;  // or a direct ray test (surfaces)
};

std::function<bool(const Vec3&)> solid(P kind, Affine toWorld, std::vector<double> args = {}) {
    const Affine inv = toWorld.inverse();
    return [=](const Vec3& p) { return insidePrimitive(kind, inv.point(p), args); };
}

bool rayTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 e1 = b - a, e2 = c - a, pv = cross(d, e2);
    const double det = dot(e1, pv);
    if (std::fabs(det) < 1e-12) return false;
    const Vec3 tv = o - a;
    const double u = dot(tv, pv) / det;
    const Vec3 qv = cross(tv, e1);
    const double v = dot(d, qv) / det;
    const double t = dot(e2, qv) / det;
    return u >= 0 && v >= 0 && u + v <= 1 && t > 0;
}

Affine mat(TransformOp op, std::vector<double> a) {
    return makeTransform(op, a.data());
}

TEST(PovRay, SilhouettesMatchTheLanguagesSolids) {
    if (!povtest::povrayInstalled())
        GTEST_SKIP() << "povray is not installed (apt-get install povray)";
    const int W = 80, H = 60;
    Camera cam;
    cam.location = {3, -6, 2.5};
    cam.lookAt = {0.3, 0, 0.2};
    cam.sky = {0, 0, 1};
    cam.angle = 40;
    const Pinhole pin(cam, W, H);

    // Transforms chosen so that any mix-up (axis, handedness, transposition, inside side)
    // changes the silhouette.
    const Affine tilt = mat(TransformOp::RotY, {40}) * mat(TransformOp::Scale, {1.2, 0.8, 1.6});
    const Affine spin = mat(TransformOp::RotZ, {25}) * mat(TransformOp::RotX, {60});
    const Affine shear = mat(TransformOp::Move, {0.2, 0, -0.3}) *
                         mat(TransformOp::ZShear, {0.5, 0.2}) * mat(TransformOp::RotZ, {30});
    auto node = [](Graph& g, const Affine& m, NodeId child) {
        std::vector<double> a(12);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) a[3 * j + i] = m.l[i][j];
        a[9] = m.t.x, a[10] = m.t.y, a[11] = m.t.z;
        return transform(g, TransformOp::Matrix, a, child);
    };
    std::vector<SilhouetteCase> cases;
    for (P k : {P::Sphere, P::Cube, P::Cylinder, P::Cone, P::Tetrahedron}) {
        for (const Affine* m : {&tilt, &spin, &shear}) {
            cases.push_back({fmt::format("primitive{}_{}", int(k),
                                         m == &tilt   ? "tilt"
                                         : m == &spin ? "spin"
                                                      : "shear"),
                             [=](Graph& g) { return node(g, *m, primitive(g, k)); }, solid(k, *m),
                             nullptr});
        }
    }
    cases.push_back({"torus",
                     [&](Graph& g) {
                         return node(g, spin, primitive(g, P::Torus, {1.2, 0.35}));
                     },
                     solid(P::Torus, spin, {1.2, 0.35}), nullptr});
    cases.push_back({"torus_tilt",
                     [&](Graph& g) {
                         return node(g, tilt, primitive(g, P::Torus, {1, 0.5}));
                     },
                     solid(P::Torus, tilt, {1, 0.5}), nullptr});
    {
        // plane ∩ sphere, tilted: the half of the sphere on the side z <= 0 of the plane.
        const Affine pl = mat(TransformOp::RotY, {35}) * mat(TransformOp::Move, {0, 0, 0.3});
        const auto inPlane = solid(P::Plane, pl), inSphere = solid(P::Sphere, Affine{});
        cases.push_back({"plane_cap",
                         [=](Graph& g) {
                             return g.addOperator(
                                 CsgOp::Intersection,
                                 {node(g, pl, primitive(g, P::Plane)), primitive(g, P::Sphere)});
                         },
                         [=](const Vec3& p) { return inPlane(p) && inSphere(p); }, nullptr});
    }
    {
        // cube \ sphere \ cylinder: a bite out of a corner and a hole.
        const Affine s = mat(TransformOp::Move, {1, -1, 1}) * mat(TransformOp::UScale, {0.9});
        const Affine c =
            mat(TransformOp::Move, {0, 0, -2}) * mat(TransformOp::Scale, {0.4, 0.4, 4});
        const auto inCube = solid(P::Cube, spin), inS = solid(P::Sphere, spin * s),
                   inC = solid(P::Cylinder, spin * c);
        cases.push_back({"difference",
                         [=](Graph& g) {
                             return node(g, spin,
                                         g.addOperator(CsgOp::Difference,
                                                       {primitive(g, P::Cube),
                                                        node(g, s, primitive(g, P::Sphere)),
                                                        node(g, c, primitive(g, P::Cylinder))}));
                         },
                         [=](const Vec3& p) { return inCube(p) && !inS(p) && !inC(p); }, nullptr});
    }
    {
        // Triangles: tri1, tri2 and a general one, tilted.
        const Affine m = spin * mat(TransformOp::UScale, {1.5});
        const std::vector<double> corners = {0.2, 0.3, 0.9, -0.8, 0.5, 0.2, 0.1, -0.9, 0.4};
        cases.push_back(
            {"triangles",
             [=](Graph& g) {
                 return node(
                     g, m,
                     g.addOperator(CsgOp::Union, {primitive(g, P::Tri1), primitive(g, P::Tri2),
                                                  primitive(g, P::Triangle, corners)}));
             },
             nullptr,
             [=](const Vec3& o, const Vec3& d) {
                 const Vec3 c[3][3] = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                       {{0, 0, 0}, {-1, 0, 0}, {0, -1, 0}},
                                       {{corners[0], corners[1], corners[2]},
                                        {corners[3], corners[4], corners[5]},
                                        {corners[6], corners[7], corners[8]}}};
                 for (const auto& t : c)
                     if (rayTriangle(o, d, m.point(t[0]), m.point(t[1]), m.point(t[2])))
                         return true;
                 return false;
             }});
    }

    std::vector<povtest::PovJob> jobs;
    for (const SilhouetteCase& k : cases) {
        Graph g;
        defaultScene(g);
        g.materials[0].ambient = 1;  // every visible point of the object is white
        g.materials[0].diffuse = 0;
        g.scene.camera = cam;
        g.axiom = k.build(g);
        const ExpandedTree t = expand(g);
        std::ostringstream os;
        PovOptions opt;
        opt.width = W;
        opt.height = H;
        writePov(g, t, os, opt);
        jobs.push_back({k.name, os.str(), W, H});
    }
    const std::vector<povtest::PovRun> runs = povtest::renderPovMany(jobs);
    for (size_t c = 0; c < cases.size(); ++c) {
        const SilhouetteCase& k = cases[c];
        const povtest::PovRun& r = runs[c];
        ASSERT_EQ(r.status, 0) << k.name << "\n" << r.log;
        EXPECT_EQ(r.problems(), "") << k.name;
        ASSERT_EQ(r.width, W) << k.name;
        ASSERT_EQ(r.height, H) << k.name;
        int onlyPov = 0, onlyExpected = 0, covered = 0;
        std::string picture;
        for (int j = 0; j < H; ++j) {
            for (int i = 0; i < W; ++i) {
                const Vec3 d = pin.ray(i, j, W, H);
                bool expected = false;
                if (k.hit) {
                    expected = k.hit(pin.eye, d);
                } else {
                    // March through the sphere of radius 3.5 about the origin that holds
                    // every test object.
                    const double b = dot(pin.eye, d), c = dot(pin.eye, pin.eye) - 3.5 * 3.5;
                    const double disc = b * b - c;
                    if (disc > 0)
                        for (double s = -b - std::sqrt(disc), end = -b + std::sqrt(disc);
                             s < end && !expected; s += 0.004)
                            expected = k.inside(pin.eye + d * s);
                }
                const bool got = r.at(i, j, 0) > 128;
                covered += expected;
                onlyPov += got && !expected;
                onlyExpected += expected && !got;
                picture += got == expected ? (got ? '#' : '.') : (got ? 'P' : 'e');
            }
            picture += '\n';
        }
        EXPECT_GT(covered, W * H / 30) << k.name << ": the object is too small to test anything";
        // Marching can step over a thin chord near a corner (a pixel only POV-Ray covers);
        // it cannot invent coverage, so pixels only expected are held tighter.
        EXPECT_LE(onlyPov, 10) << k.name << " (P: only POV-Ray covers, e: only expected)\n"
                               << picture;
        EXPECT_LE(onlyExpected, 3) << k.name << " (P: only POV-Ray covers, e: only expected)\n"
                                   << picture;
    }
}

TEST(PovRay, ParsesAndRendersEveryPrimitiveWithoutWarnings) {
    if (!povtest::povrayInstalled())
        GTEST_SKIP() << "povray is not installed (apt-get install povray)";
    // Sierpinski order 3 beside one of each primitive, with materials and several lights.
    Graph g = sierpinski(3);
    g.materials.push_back(Material{.name = "red",
                                   .color = {0.8, 0.1, 0.1},
                                   .ambient = 0.1,
                                   .diffuse = 0.7,
                                   .phong = 0.4,
                                   .phongSize = 30,
                                   .reflection = 0});
    g.materials.push_back(Material{.name = "mirror",
                                   .color = {0.9, 0.9, 0.9},
                                   .ambient = 0.05,
                                   .diffuse = 0.3,
                                   .phong = 0.8,
                                   .phongSize = 60,
                                   .reflection = 0.5});
    g.scene.lights.push_back(Light{{-10, -5, 10}, {0.4, 0.4, 0.5}});
    g.scene.background = {0.2, 0.3, 0.5};
    std::vector<NodeId> parts = {g.axiom};
    int x = 0;
    for (P k : {P::Sphere, P::Cube, P::Cylinder, P::Cone, P::Tetrahedron, P::Tri1, P::Tri2}) {
        parts.push_back(
            paint(g, 1 + (x % 2),
                  transform(g, TransformOp::Move, {3.0 + 2.5 * x, 0, 0}, primitive(g, k))));
        ++x;
    }
    parts.push_back(transform(g, TransformOp::Move, {-3, 0, 0}, primitive(g, P::Torus, {1, 0.3})));
    parts.push_back(transform(g, TransformOp::Move, {0, 0, -1.5}, primitive(g, P::Plane)));
    g.axiom = g.addOperator(CsgOp::Union, parts);
    g.scene.camera.location = {5, -20, 3};
    g.scene.camera.lookAt = {5, 0, 0.5};
    PovOptions opt;
    opt.width = 64;
    opt.height = 48;
    const std::string text = exportText(g, opt);
    if (const char* dump = std::getenv("PCSG_DUMP_POV")) std::ofstream(dump) << text;
    const povtest::PovRun r = povtest::renderPov(text, 64, 48, "all");
    ASSERT_EQ(r.status, 0) << r.log;
    EXPECT_EQ(r.problems(), "") << r.log;
    EXPECT_EQ(r.width, 64);
    // The background shows, and so does something else.
    int background = 0;
    for (int j = 0; j < 48; ++j)
        for (int i = 0; i < 64; ++i)
            background += r.at(i, j, 0) == r.at(0, 0, 0) && r.at(i, j, 2) == r.at(0, 0, 2);
    EXPECT_GT(background, 100);
    EXPECT_LT(background, 64 * 48 - 100);
}

TEST(PovRay, AnEmptySceneRendersTheBackground) {
    if (!povtest::povrayInstalled())
        GTEST_SKIP() << "povray is not installed (apt-get install povray)";
    Graph g;
    defaultScene(g);
    g.scene.background = {0, 1, 0};
    g.axiom = primitive(g, P::Empty);
    const povtest::PovRun r = povtest::renderPov(exportText(g), 16, 12, "empty");
    ASSERT_EQ(r.status, 0) << r.log;
    ASSERT_EQ(r.width, 16);
    EXPECT_EQ(r.at(5, 5, 1), 255);
    EXPECT_EQ(r.at(5, 5, 0), 0);
}

}  // namespace
}  // namespace pcsg
