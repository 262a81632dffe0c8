// Comparing two compiled graphs in tests (header-only, gtest): the formatter's and the
// fuzz generator's round trips compile a text twice and expect the same graph.
#pragma once

#include <gtest/gtest.h>

#include "graph.h"

namespace pcsg::testing {

inline void expectSameVec(const Vec3& a, const Vec3& b) {
    EXPECT_EQ(a.x, b.x);
    EXPECT_EQ(a.y, b.y);
    EXPECT_EQ(a.z, b.z);
}

// The directives: camera, lights, background, settings.
inline void expectSameScene(const Scene& a, const Scene& b) {
    expectSameVec(a.camera.location, b.camera.location);
    expectSameVec(a.camera.lookAt, b.camera.lookAt);
    expectSameVec(a.camera.sky, b.camera.sky);
    EXPECT_EQ(a.camera.angle, b.camera.angle);
    ASSERT_EQ(a.lights.size(), b.lights.size());
    for (size_t k = 0; k < a.lights.size(); ++k) {
        expectSameVec(a.lights[k].position, b.lights[k].position);
        expectSameVec(a.lights[k].color, b.lights[k].color);
        expectSameVec(a.lights[k].pointAt, b.lights[k].pointAt);
        expectSameVec(a.lights[k].axis1, b.lights[k].axis1);
        expectSameVec(a.lights[k].axis2, b.lights[k].axis2);
        EXPECT_EQ(a.lights[k].size1, b.lights[k].size1);
        EXPECT_EQ(a.lights[k].size2, b.lights[k].size2);
        EXPECT_EQ(a.lights[k].adaptive, b.lights[k].adaptive);
        EXPECT_EQ(a.lights[k].spotlight, b.lights[k].spotlight);
        EXPECT_EQ(a.lights[k].shadowless, b.lights[k].shadowless);
        EXPECT_EQ(a.lights[k].radius, b.lights[k].radius);
        EXPECT_EQ(a.lights[k].fadeDistance, b.lights[k].fadeDistance);
    }
    EXPECT_EQ(a.fog.enabled, b.fog.enabled);
    EXPECT_EQ(a.fog.type, b.fog.type);
    EXPECT_EQ(a.fog.distance, b.fog.distance);
    expectSameVec(a.fog.color, b.fog.color);
    EXPECT_EQ(a.fog.alt, b.fog.alt);
    expectSameVec(a.background, b.background);
    EXPECT_EQ(a.settings.seed, b.settings.seed);
    EXPECT_EQ(a.settings.maxDepth, b.settings.maxDepth);
}

// The graphs agree in everything but source locations and texts.
inline void expectSameGraph(const Graph& a, const Graph& b) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (size_t k = 0; k < a.nodes.size(); ++k) {
        EXPECT_EQ(a.nodes[k].kind, b.nodes[k].kind) << k;
        EXPECT_EQ(a.nodes[k].payload, b.nodes[k].payload) << k;
        EXPECT_EQ(a.nodes[k].firstChild, b.nodes[k].firstChild) << k;
        EXPECT_EQ(a.nodes[k].childCount, b.nodes[k].childCount) << k;
    }
    EXPECT_EQ(a.edges, b.edges);
    ASSERT_EQ(a.code.size(), b.code.size());
    for (size_t k = 0; k < a.code.size(); ++k) {
        EXPECT_EQ(a.code[k].op, b.code[k].op) << k;
        EXPECT_EQ(a.code[k].argc, b.code[k].argc) << k;
        EXPECT_EQ(a.code[k].a, b.code[k].a) << k;
        EXPECT_EQ(a.code[k].imm, b.code[k].imm) << k;
    }
    ASSERT_EQ(a.exprs.size(), b.exprs.size());
    for (size_t k = 0; k < a.exprs.size(); ++k) {
        EXPECT_EQ(a.exprs[k].begin, b.exprs[k].begin) << k;
        EXPECT_EQ(a.exprs[k].end, b.exprs[k].end) << k;
        EXPECT_EQ(a.exprs[k].constant, b.exprs[k].constant) << k;
    }
    ASSERT_EQ(a.modules.size(), b.modules.size());
    for (size_t k = 0; k < a.modules.size(); ++k) {
        EXPECT_EQ(a.modules[k].name, b.modules[k].name);
        EXPECT_EQ(a.modules[k].select, b.modules[k].select);
        EXPECT_EQ(a.modules[k].conditions, b.modules[k].conditions);
    }
    EXPECT_EQ(a.args, b.args);
    EXPECT_EQ(a.slotNames, b.slotNames);
    EXPECT_EQ(a.transforms.size(), b.transforms.size());
    EXPECT_EQ(a.assignments.size(), b.assignments.size());
    ASSERT_EQ(a.primitives.size(), b.primitives.size());
    for (size_t k = 0; k < a.primitives.size(); ++k)
        EXPECT_EQ(a.primitives[k].values, b.primitives[k].values) << k;
    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (size_t k = 0; k < a.materials.size(); ++k) {
        const Material &m = a.materials[k], &n = b.materials[k];
        EXPECT_EQ(m.name, n.name);
        expectSameVec(m.color, n.color);
        EXPECT_EQ(std::vector<double>({m.ambient, m.diffuse, m.phong, m.phongSize, m.reflection,
                                       m.brilliance, m.specular, m.roughness, m.metallic,
                                       m.minReflection(), m.ior, m.reflectMetallic}),
                  std::vector<double>({n.ambient, n.diffuse, n.phong, n.phongSize, n.reflection,
                                       n.brilliance, n.specular, n.roughness, n.metallic,
                                       n.minReflection(), n.ior, n.reflectMetallic}));
        EXPECT_EQ(m.fresnel, n.fresnel);
        EXPECT_EQ(m.conserveEnergy, n.conserveEnergy);
    }
    expectSameScene(a.scene, b.scene);
    EXPECT_EQ(a.timedValues.size(), b.timedValues.size());
}

}  // namespace pcsg::testing
