// Scene directives that read the time (docs/language.md section 11): a camera may fly,
// lights, background and materials may change; settings stay constants, and parameters
// stay forbidden in directives.
#include "scene_time.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "compile_test_util.h"
#include "eval.h"

namespace pcsg {
namespace {

using testing::compile;

TEST(SceneTime, ACameraFliesWithTheClock) {
    auto c = compile(
        "camera { location <4*cos(clock*360), 4*sin(clock*360), 2> look_at <0,0,0> }\n"
        "sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    EXPECT_EQ(g.timedValues.size(), 2u);  // x and y; z is a constant
    setTime(g, Time{0, 1});
    const Vec3 a = g.scene.camera.location;
    EXPECT_DOUBLE_EQ(a.x, 4);
    EXPECT_DOUBLE_EQ(a.y, 0);
    EXPECT_DOUBLE_EQ(a.z, 2);
    setTime(g, Time{0.25, 2});
    const Vec3 b = g.scene.camera.location;
    EXPECT_DOUBLE_EQ(b.x, 0);  // cos(90) is exact
    EXPECT_DOUBLE_EQ(b.y, 4);
    EXPECT_DOUBLE_EQ(b.z, 2);
    EXPECT_EQ(g.time.clock, 0.25);
    EXPECT_EQ(g.time.frame, 2);
}

TEST(SceneTime, TheCompiledSceneHoldsTheStillsValues) {
    auto c = compile("camera { location <1 + clock, -5, 2 + frame> }\nsphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    EXPECT_DOUBLE_EQ(c->graph->scene.camera.location.x, 1);
    EXPECT_DOUBLE_EQ(c->graph->scene.camera.location.z, 3);
}

TEST(SceneTime, LightsBackgroundAndMaterialsFollowTheTime) {
    auto c = compile(
        "light { position <10, -20, 30> }\nlight { position <clock, 0, 9> color <1, frame, 1> }\n"
        "background <0, 0, clock>\n"
        "material m { color <clock, 0.5, 0.5> ambient 0.1 * frame phong_size 10 + clock }\n"
        "paint(m) sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    setTime(g, Time{0.5, 3});
    ASSERT_EQ(g.scene.lights.size(), 2u);
    EXPECT_EQ(g.scene.lights[0].position.x, 10);
    EXPECT_EQ(g.scene.lights[1].position.x, 0.5);
    EXPECT_EQ(g.scene.lights[1].color.y, 3);
    EXPECT_EQ(g.scene.background.z, 0.5);
    const Material& m = g.materials.back();
    EXPECT_EQ(m.color.x, 0.5);
    EXPECT_DOUBLE_EQ(m.ambient, 0.3);
    EXPECT_EQ(m.phongSize, 10.5);
    EXPECT_EQ(m.diffuse, 0.6);  // untouched
}

// Values inside a material's blocks follow the time too, each into its own field.
TEST(SceneTime, MaterialBlockValuesFollowTheTime) {
    auto c = compile(
        "material m { pigment { color rgb <0.2, clock, 0.4> }\n"
        "  finish { brilliance 1 + clock specular clock / 2 roughness 0.1 * frame metallic clock\n"
        "           reflection { clock / 4, clock } }\n"
        "  interior { ior 1 + clock } }\n"
        "paint(m) sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    setTime(g, Time{0.5, 2});
    const Material& m = g.materials.back();
    EXPECT_EQ(m.color, (Vec3{0.2, 0.5, 0.4}));
    EXPECT_EQ(m.brilliance, 1.5);
    EXPECT_EQ(m.specular, 0.25);
    EXPECT_DOUBLE_EQ(m.roughness, 0.2);
    EXPECT_EQ(m.metallic, 0.5);
    EXPECT_EQ(m.minReflection(), 0.125);
    EXPECT_EQ(m.reflection, 0.5);
    EXPECT_EQ(m.ior, 1.5);
}

TEST(SceneTime, ParametersAndRandomnessStayForbiddenInDirectives) {
    auto c = compile("camera { location <c, -5, 2> }\n{c = 1} sphere\n");
    EXPECT_FALSE(c->graph);
    EXPECT_NE(c->errors().find("constants, not parameters"), std::string::npos) << c->errors();
    auto r = compile("camera { location <clock + rand(), -5, 2> }\nsphere\n");
    EXPECT_FALSE(r->graph);
    EXPECT_NE(r->errors().find("rand()"), std::string::npos) << r->errors();
}

TEST(SceneTime, SettingsStayConstants) {
    auto c = compile("settings { seed 3 + clock }\nsphere\n");
    EXPECT_FALSE(c->graph);
    EXPECT_NE(c->errors().find("settings are constants"), std::string::npos) << c->errors();
}

TEST(SceneTime, ABadValueAtSomeTimeIsARunTimeErrorNamingTheTime) {
    auto c = compile("camera { location <0, -5, 2> angle 40 + clock * 200 }\nsphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    EXPECT_NO_THROW(setTime(g, Time{0.5, 1}));
    try {
        setTime(g, Time{0.75, 4});
        FAIL() << "no error";
    } catch (const RuntimeError& e) {
        EXPECT_NE(e.message.find("clock 0.75, frame 4"), std::string::npos) << e.message;
        EXPECT_NE(e.message.find("angle"), std::string::npos) << e.message;
    }
    auto d = compile("camera { location <0, -5 * clock, 0> look_at <0, 0, 0> }\nsphere\n");
    ASSERT_TRUE(d->graph) << d->errors();  // the still (clock 0) is checked when rendered
    EXPECT_THROW(setTime(*d->graph, Time{0, 1}), RuntimeError);
    EXPECT_NO_THROW(setTime(*d->graph, Time{1, 1}));
    auto n = compile("background <0, 0, 1 / clock>\nsphere\n");
    ASSERT_TRUE(n->graph) << n->errors();
    EXPECT_THROW(setTime(*n->graph, Time{0, 1}), RuntimeError);
}

}  // namespace
}  // namespace pcsg
