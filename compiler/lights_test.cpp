// The builder's light { } and fog { } (docs/language.md section 10): every item lands in
// its field, spotlight values and point_at may follow the time, area_light's are constants.
#include <gtest/gtest.h>

#include "compile_test_util.h"
#include "scene_time.h"

namespace pcsg {
namespace {

using testing::compile;

TEST(LightItems, EveryItemLandsInItsField) {
    auto c = compile(
        "light { position <1, 2, 3>  color <0.5, 0.6, 0.7>  spotlight  point_at <4, 5, 6>\n"
        "        radius 12  falloff 20  tightness 3  fade_distance 7  fade_power 2 }\n"
        "light { area_light <1, 0, 0>, <0, 2, 0>, 5, 3  adaptive 2  jitter  circular  orient\n"
        "        shadowless }\n"
        "sphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const auto& lights = c->graph->scene.lights;
    ASSERT_EQ(lights.size(), 2u);
    const Light& s = lights[0];
    EXPECT_TRUE(s.spotlight);
    EXPECT_FALSE(s.shadowless);
    EXPECT_EQ(s.pointAt.z, 6);
    EXPECT_EQ(s.radius, 12);
    EXPECT_EQ(s.falloff, 20);
    EXPECT_EQ(s.tightness, 3);
    EXPECT_EQ(s.fadeDistance, 7);
    EXPECT_EQ(s.fadePower, 2);
    EXPECT_FALSE(s.areaLight());
    const Light& a = lights[1];
    EXPECT_TRUE(a.areaLight());
    EXPECT_EQ(a.axis2.y, 2);
    EXPECT_EQ(a.size1, 5);
    EXPECT_EQ(a.size2, 3);
    EXPECT_EQ(a.adaptive, 2);
    EXPECT_TRUE(a.jitter && a.circular && a.orient && a.shadowless);
    EXPECT_FALSE(c->graph->scene.fog.enabled);
}

TEST(LightItems, DefaultsArePovRays) {
    auto c = compile("light { spotlight }\nsphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Light& l = c->graph->scene.lights[0];
    EXPECT_EQ(l.radius, 30);
    EXPECT_EQ(l.falloff, 45);
    EXPECT_EQ(l.tightness, 0);
    EXPECT_EQ(l.pointAt.z, 1);
    EXPECT_EQ(l.adaptive, 100);
}

TEST(LightItems, SpotValuesFollowTheTime) {
    auto c = compile(
        "light { spotlight  point_at <clock, 0, 0>  radius 10 + clock  fade_distance frame\n"
        "        fade_power 1 }\nsphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    Graph& g = *c->graph;
    setTime(g, Time{0.5, 4});
    EXPECT_EQ(g.scene.lights[0].pointAt.x, 0.5);
    EXPECT_EQ(g.scene.lights[0].radius, 10.5);
    EXPECT_EQ(g.scene.lights[0].fadeDistance, 4);
}

TEST(FogItems, ConstantAndGroundFog) {
    auto c = compile(
        "fog { fog_type 2  distance 3  color <0.1, 0.2, 0.3>  filter 0.5  transmit 0.25\n"
        "      fog_offset -1  fog_alt 0.5 }\nsphere\n");
    ASSERT_TRUE(c->graph) << c->errors();
    const Fog& f = c->graph->scene.fog;
    EXPECT_TRUE(f.enabled);
    EXPECT_EQ(f.type, 2);
    EXPECT_EQ(f.distance, 3);
    EXPECT_EQ(f.color.z, 0.3);
    EXPECT_EQ(f.filter, 0.5);
    EXPECT_EQ(f.transmit, 0.25);
    EXPECT_EQ(f.offset, -1);
    EXPECT_EQ(f.alt, 0.5);
    auto plain = compile("fog { distance 5  color <1, 1, 1> }\nsphere\n");
    ASSERT_TRUE(plain->graph) << plain->errors();
    EXPECT_EQ(plain->graph->scene.fog.type, 1);
    EXPECT_TRUE(plain->graph->scene.fog.enabled);
}

}  // namespace
}  // namespace pcsg
