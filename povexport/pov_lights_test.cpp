// The exporter's lights and fog (pov_lights.h): POV-Ray 3.7 text, spotlight before its
// parameters, ground fog with `up z`.
#include "pov_lights.h"

#include <gtest/gtest.h>

namespace pcsg {
namespace {

TEST(PovLights, PointSpotAreaAndShadowless) {
    Light point;
    EXPECT_EQ(povLight(point), "light_source { <10,-20,30> color rgb <1,1,1> }");
    Light spot;
    spot.spotlight = true;
    spot.pointAt = {1, 2, 0};
    spot.radius = 12.5;
    spot.fadeDistance = 3;
    spot.fadePower = 2;
    EXPECT_EQ(povLight(spot),
              "light_source { <10,-20,30> color rgb <1,1,1> spotlight point_at <1,2,0> radius "
              "12.5 falloff 45 tightness 0 fade_distance 3 fade_power 2 }");
    Light area;
    area.axis1 = {2, 0, 0};
    area.axis2 = {0, 0, 2};
    area.size1 = 4;
    area.size2 = 3;
    area.adaptive = 1;
    area.jitter = area.orient = area.shadowless = true;
    EXPECT_EQ(povLight(area),
              "light_source { <10,-20,30> color rgb <1,1,1> shadowless area_light <2,0,0>, "
              "<0,0,2>, 4, 3 adaptive 1 jitter orient }");
}

TEST(PovLights, FogConstantAndGround) {
    Fog none;
    EXPECT_EQ(povFog(none), "");
    Fog f;
    f.enabled = true;
    f.distance = 5;
    f.color = {0.5, 0.5, 0.6};
    f.filter = 0.25;
    EXPECT_EQ(povFog(f), "fog { fog_type 1 distance 5 color rgbft <0.5,0.5,0.6,0.25,0> }");
    f.type = 2;
    f.offset = -1;
    f.alt = 0.5;
    EXPECT_EQ(povFog(f),
              "fog { fog_type 2 distance 5 color rgbft <0.5,0.5,0.6,0.25,0> fog_offset -1 "
              "fog_alt 0.5 up z }");
}

}  // namespace
}  // namespace pcsg
