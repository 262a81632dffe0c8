// The pigment and normal as POV-Ray text, as read.
#include "pov_texture.h"

#include <gtest/gtest.h>

#include "compile_test_util.h"

namespace pcsg {
namespace {

Material materialOf(const std::string& body) {
    auto c = testing::compile("material m { " + body + " }\npaint(m) sphere\n");
    EXPECT_TRUE(c->graph) << c->errors();
    return c->graph ? c->graph->materials.back() : Material{};
}

TEST(PovTexture, PlainPigment) {
    EXPECT_EQ(povPigment(materialOf("color <1, 0.5, 0>")), "pigment { color rgb <1,0.5,0> }");
    EXPECT_EQ(povNormal(materialOf("color <1, 0.5, 0>")), "");
}

TEST(PovTexture, PatternWithItsItemsInOrder) {
    EXPECT_EQ(povPigment(materialOf("pigment { checker rgb 1 rgb 0 scale 2 rotate <0, 0, 45> "
                                    "translate <1, 0, 0> }")),
              "pigment { checker color rgb <1,1,1> color rgb <0,0,0> scale <2,2,2> "
              "rotate <0,0,45> translate <1,0,0> }");
    EXPECT_EQ(povPigment(materialOf("pigment { gradient x frequency 2 phase 0.5 color_map { [0 "
                                    "rgb 0] [1 rgb 1] } }")),
              "pigment { gradient <1,0,0> color_map { [0 color rgb <0,0,0>] [1 color rgb "
              "<1,1,1>] } frequency 2 phase 0.5 }");
    EXPECT_EQ(povPigment(materialOf("pigment { agate agate_turb 0.3 turbulence 0.5 }")),
              "pigment { agate agate_turb 0.3 turbulence <0.5,0.5,0.5> octaves 6 omega 0.5 "
              "lambda 2 }");
    EXPECT_EQ(povPigment(materialOf("pigment { spotted }")), "pigment { spotted }");
}

TEST(PovTexture, Normal) {
    EXPECT_EQ(povNormal(materialOf("normal { waves 0.3 frequency 4 scale 0.5 }")),
              " normal { waves 0.3 frequency 4 scale <0.5,0.5,0.5> }");
}

}  // namespace
}  // namespace pcsg
