#include <gtest/gtest.h>

#include <cmath>

#include "cohort/core/gpu_scene.h"

using namespace cohort;

namespace {

scene::Mesh quad_mesh(const std::string& name, int material, float z) {
  scene::Mesh m;
  m.name = name;
  for (glm::vec2 p : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)}) {
    scene::Vertex v;
    v.position = glm::vec3(p, z);
    v.st = p;
    m.vertices.push_back(v);
  }
  m.indices = {0, 1, 2, 0, 2, 3};
  m.surfaces.push_back({material, 0, 6});
  return m;
}

float plane(const float* p, glm::vec3 x) { return p[0] * x.x + p[1] * x.y + p[2] * x.z + p[3]; }

}  // namespace

TEST(GpuScene, CompilesWorldAndEntityInstancesWithMasks) {
  scene::Scene s;
  s.materials.resize(2);
  s.materials[0].name = "a";
  s.materials[1].name = "b";
  s.meshes.push_back(quad_mesh("_area0", 0, 0.0f));
  s.meshes.push_back(quad_mesh("_area1", -1, 1.0f));   // no material: gets the default one
  s.meshes.push_back(quad_mesh("crate", 1, 0.0f));
  s.area_meshes = {0, 1};
  scene::Entity e1, e2, e3;
  e1.mesh = 2;
  e1.origin = {10, 0, 0};
  e2.mesh = 2;
  e2.no_shadows = true;
  e3.mesh = -1;  // a speaker, say: no geometry
  s.entities = {e1, e2, e3};

  core::CompiledScene c = core::compile_scene(s);
  const commit::TracerScene& ts = c.tracer_scene;
  ASSERT_EQ(ts.blases.size(), 2u) << "one world BLAS, one for the shared crate mesh";
  EXPECT_EQ(c.blas_of_mesh[0], c.world_blas);
  EXPECT_EQ(c.blas_of_mesh[1], c.world_blas);
  EXPECT_NE(c.blas_of_mesh[2], c.world_blas);
  EXPECT_EQ(ts.blases[c.world_blas].tri_count, 4u);
  EXPECT_EQ(ts.triangles.size(), 6u) << "the crate's triangles are stored once";
  EXPECT_EQ(ts.vertices.size(), 12u);
  ASSERT_EQ(ts.instances.size(), 3u);
  int world = 0, shadowless = 0, casting = 0;
  for (const KInstance& inst : ts.instances) {
    if (inst.entity == K_NONE) {
      ++world;
      EXPECT_EQ(inst.mask, K_MASK_PRIMARY | K_MASK_SHADOW);
    } else if (inst.entity == 1u) {
      ++shadowless;
      EXPECT_EQ(inst.mask, K_MASK_PRIMARY);
    } else {
      ++casting;
      EXPECT_EQ(inst.mask, K_MASK_PRIMARY | K_MASK_SHADOW);
      EXPECT_FLOAT_EQ(inst.object_to_world[3], 10.0f);
    }
  }
  EXPECT_EQ(world + shadowless + casting, 3);
  EXPECT_EQ(shadowless, 1);
  ASSERT_EQ(ts.materials.size(), 3u);
  int defaulted = 0;
  for (const KTriangle& t : ts.triangles) defaulted += t.material == core::default_material_index(s);
  EXPECT_EQ(defaulted, 2);
  EXPECT_FALSE(ts.tlas_nodes.empty());
}

TEST(GpuScene, TexturesCarryMipChainsAndPerUseFlags) {
  scene::Scene s;
  scene::Image colour;
  colour.name = "c";
  colour.width = 4;
  colour.height = 2;
  colour.rgba.assign(4 * 2 * 4, 0);
  for (int i = 0; i < 8; ++i) colour.rgba[size_t(i) * 4] = uint8_t(i * 20);  // R = 0, 20, ..., 140
  scene::Image normals = colour;
  normals.name = "n";
  normals.is_normal_map = true;
  scene::Image broken;
  broken.name = "missing";
  s.images = {colour, normals, broken};
  core::CompiledScene c = core::compile_scene(s);
  const commit::TracerScene& ts = c.tracer_scene;
  ASSERT_EQ(ts.textures.size(), 9u);
  EXPECT_EQ(ts.texels.size(), 2u * (8 + 2 + 1)) << "4x2, 2x1, 1x1 for each of the two valid images";
  const KTexture& surface = ts.textures[core::texture_slot(0, core::TextureUse::Surface, s)];
  const KTexture& light = ts.textures[core::texture_slot(0, core::TextureUse::LightImage, s)];
  const KTexture& falloff = ts.textures[core::texture_slot(0, core::TextureUse::Falloff, s)];
  const KTexture& normal = ts.textures[core::texture_slot(1, core::TextureUse::Surface, s)];
  EXPECT_EQ(surface.flags_and_levels, K_TEX_SRGB | (3u << 8));
  EXPECT_EQ(light.flags_and_levels, K_TEX_SRGB | K_TEX_CLAMP | (3u << 8));
  EXPECT_EQ(falloff.flags_and_levels, K_TEX_CLAMP | (3u << 8));
  EXPECT_EQ(normal.flags_and_levels & 0xFFu, K_TEX_NORMAL);
  EXPECT_EQ(surface.offset, light.offset) << "uses share texels";
  // Level 1 texel 0 averages (0, 20) and (80, 100): R = 50.
  EXPECT_EQ(ts.texels[surface.offset + 8] & 0xFFu, 50u);
  EXPECT_EQ(core::texture_slot(2, core::TextureUse::Surface, s), K_NONE) << "empty image";
  EXPECT_EQ(core::texture_slot(-1, core::TextureUse::Surface, s), K_NONE);
}

TEST(GpuScene, PointLightPlanesSpanTheRotatedBox) {
  scene::Scene s;
  scene::Light l;
  l.origin = {100, 50, 20};
  l.radius = {40, 20, 10};
  l.color = {0.5f, 1.0f, 0.25f};
  l.center = {5, 0, 0};
  // Light x axis along world +Y, y along world -X.
  l.axis = glm::mat3(glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1));
  KLight k = core::to_klight(l, s);
  EXPECT_EQ(k.type, K_LIGHT_POINT);
  EXPECT_NEAR(plane(k.plane_s, l.origin), 0.5f, 1e-5f);
  EXPECT_NEAR(plane(k.plane_t, l.origin), 0.5f, 1e-5f);
  EXPECT_NEAR(plane(k.plane_f, l.origin), 0.5f, 1e-5f);
  EXPECT_NEAR(plane(k.plane_q, l.origin), 1.0f, 1e-5f);
  EXPECT_NEAR(plane(k.plane_s, l.origin + glm::vec3(0, 40, 0)), 1.0f, 1e-5f);
  EXPECT_NEAR(plane(k.plane_t, l.origin + glm::vec3(20, 0, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(plane(k.plane_f, l.origin - glm::vec3(0, 0, 10)), 0.0f, 1e-5f);
  EXPECT_FLOAT_EQ(k.color[0], 1.0f) << "r_lightScale 2 x _color";
  EXPECT_FLOAT_EQ(k.color[1], 2.0f);
  EXPECT_NEAR(k.center[1], 55.0f, 1e-5f) << "light_center is rotated by the axis";
  EXPECT_EQ(k.light_tex, K_NONE);
  EXPECT_EQ(k.falloff_tex, K_NONE);
  EXPECT_NEAR(k.volume_reach, std::sqrt(40.0f * 40.0f + 20.0f * 20.0f + 10.0f * 10.0f), 1e-3f)
      << "the fog reject's bound: the box's farthest corner from its origin";
  // A skewed axis (not a rotation): the farthest corner is still the bound.
  l.axis = glm::mat3(glm::vec3(1, 0, 0), glm::vec3(1, 1, 0), glm::vec3(0, 0, 2));
  k = core::to_klight(l, s);
  EXPECT_NEAR(k.volume_reach, glm::length(glm::vec3(40 + 20, 20, 20)), 1e-3f);
}

TEST(GpuScene, ProjectedLightPlanesMapTheFrustum) {
  scene::Scene s;
  scene::Light l;
  l.type = scene::LightType::Projected;
  l.origin = {0, 0, 100};
  l.target = {0, 0, -100};
  l.right = {50, 0, 0};
  l.up = {0, 30, 0};
  l.start = {0, 0, -10};
  l.end = {0, 0, -110};
  l.has_start_end = true;
  KLight k = core::to_klight(l, s);
  auto st = [&](glm::vec3 p) {
    float q = plane(k.plane_q, p);
    return glm::vec2(plane(k.plane_s, p) / q, plane(k.plane_t, p) / q);
  };
  glm::vec3 target = l.origin + l.target;
  EXPECT_NEAR(st(target).x, 0.5f, 1e-5f);
  EXPECT_NEAR(st(target).y, 0.5f, 1e-5f);
  EXPECT_NEAR(st(target + l.right).x, 1.0f, 1e-5f);
  EXPECT_NEAR(st(target - l.right).x, 0.0f, 1e-5f);
  EXPECT_NEAR(st(target + l.up).y, 0.0f, 1e-5f) << "t = 0 at the top of the image";
  EXPECT_NEAR(st(l.origin + 0.5f * (l.target + l.right)).x, 1.0f, 1e-5f) << "a frustum, not a box";
  EXPECT_NEAR(plane(k.plane_f, l.origin + l.start), 0.0f, 1e-5f);
  EXPECT_NEAR(plane(k.plane_f, l.origin + l.end), 1.0f, 1e-5f);
}

TEST(GpuScene, ParallelLightPointsTowardTheRotatedCenter) {
  scene::Scene s;
  scene::Light l;
  l.type = scene::LightType::Parallel;
  l.center = {0, 0, 2};
  l.axis = glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, -1, 0));
  KLight k = core::to_klight(l, s);
  EXPECT_EQ(k.type, K_LIGHT_PARALLEL);
  EXPECT_NEAR(k.center[0], 0.0f, 1e-6f);
  EXPECT_NEAR(k.center[1], -1.0f, 1e-6f);
  EXPECT_NEAR(k.center[2], 0.0f, 1e-6f);
}

TEST(GpuScene, InstanceTransformsAreInverses) {
  KInstance inst{};
  glm::mat3 axis(glm::vec3(0, 2, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 3));
  core::set_instance_transform(inst, {5, -6, 7}, axis);
  glm::vec3 p(1.5f, -2.0f, 0.25f);
  auto apply = [](const float* m, glm::vec3 v) {
    return glm::vec3(m[0] * v.x + m[1] * v.y + m[2] * v.z + m[3], m[4] * v.x + m[5] * v.y + m[6] * v.z + m[7],
                     m[8] * v.x + m[9] * v.y + m[10] * v.z + m[11]);
  };
  glm::vec3 w = apply(inst.object_to_world, p);
  glm::vec3 expected = axis * p + glm::vec3(5, -6, 7);
  EXPECT_NEAR(w.x, expected.x, 1e-5f);
  EXPECT_NEAR(w.y, expected.y, 1e-5f);
  EXPECT_NEAR(w.z, expected.z, 1e-5f);
  glm::vec3 back = apply(inst.world_to_object, w);
  EXPECT_NEAR(back.x, p.x, 1e-5f);
  EXPECT_NEAR(back.y, p.y, 1e-5f);
  EXPECT_NEAR(back.z, p.z, 1e-5f);
}

TEST(GpuScene, MaterialsMapBlendFlagsAndMissingSpecular) {
  scene::Scene s;
  scene::Material m;
  m.alpha_test = true;
  m.alpha_ref = 0.3f;
  m.no_shadows = true;
  m.blend = scene::BlendClass::Modulate;
  KMaterial k = core::to_kmaterial(m, s);
  EXPECT_EQ(k.blend, K_BLEND_MODULATE);
  EXPECT_EQ(k.flags & (K_MAT_ALPHA_TEST | K_MAT_NO_SHADOWS), K_MAT_ALPHA_TEST | K_MAT_NO_SHADOWS);
  EXPECT_FLOAT_EQ(k.alpha_ref, 0.3f);
  EXPECT_FLOAT_EQ(k.specular_color[0], 0.0f) << "no specular map: no specular, as in Doom 3";
  EXPECT_EQ(k.diffuse_tex, K_NONE);
  EXPECT_EQ(k.flags & (K_MAT_VERTEX_COLOR | K_MAT_INVERSE_VERTEX_COLOR), 0u);
  m.vertex_color = true;
  EXPECT_EQ(core::to_kmaterial(m, s).flags & (K_MAT_VERTEX_COLOR | K_MAT_INVERSE_VERTEX_COLOR), K_MAT_VERTEX_COLOR);
  m.vertex_color = false;
  m.inverse_vertex_color = true;
  EXPECT_EQ(core::to_kmaterial(m, s).flags & (K_MAT_VERTEX_COLOR | K_MAT_INVERSE_VERTEX_COLOR),
            K_MAT_INVERSE_VERTEX_COLOR);
}

TEST(GpuScene, VertexColoursSitBesideTheirVerticesWhiteWhereAMeshHasNone) {
  scene::Scene s;
  s.materials.emplace_back();
  scene::Mesh world = quad_mesh("_area0", 0, 0.0f);
  world.colors = {0xFF0000FFu, 0xFF00FF00u, 0xFFFF0000u, 0x80808080u};
  s.meshes.push_back(world);
  s.area_meshes.push_back(0);
  s.meshes.push_back(quad_mesh("models/plain", 0, 1.0f));   // no colours
  scene::Mesh coloured = quad_mesh("models/coloured", 0, 2.0f);
  coloured.colors.assign(4, 0xFF123456u);
  s.meshes.push_back(coloured);
  for (int mesh : {1, 2}) {
    scene::Entity e;
    e.mesh = mesh;
    s.entities.push_back(e);
  }
  core::CompiledScene compiled = core::compile_scene(s);
  const commit::TracerScene& t = compiled.tracer_scene;
  ASSERT_EQ(t.vertex_colors.size(), t.vertices.size());
  // Each mesh's vertices are a run of the pool; find them by height.
  for (size_t v = 0; v < t.vertices.size(); ++v) {
    const float z = t.vertices[v].pos[2];
    if (z == 1.0f) { EXPECT_EQ(t.vertex_colors[v], K_VERTEX_COLOR_WHITE) << "vertex " << v; }
    if (z == 2.0f) { EXPECT_EQ(t.vertex_colors[v], 0xFF123456u) << "vertex " << v; }
  }
  std::vector<KVertexColor> world_colours;
  for (size_t v = 0; v < t.vertices.size(); ++v)
    if (t.vertices[v].pos[2] == 0.0f) world_colours.push_back(t.vertex_colors[v]);
  EXPECT_EQ(world_colours, world.colors);

  s.meshes[2].colors.pop_back();   // colours for some vertices only
  EXPECT_THROW(core::compile_scene(s), std::runtime_error);
}
