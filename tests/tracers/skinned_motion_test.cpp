// Motion vectors of a skinned character (kernel/aux_outputs.h, KAuxHistory): the test map's walker, posed,
// then posed again with every joint moved by the same offset along its up axis. Each skinned point then
// moved by exactly that offset (a vertex is a bias-weighted sum over joints whose biases sum to one), so
// the motion at every pixel of the walker is the projection of its point moved back, although the
// entity's transform never changed. Without the previous pose the motion there would be zero.
#include <gtest/gtest.h>

#include <cmath>

#include "cohort/core/view.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/md5.h"
#include "cohort/scene/render_world.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

glm::vec3 load(const float* v) { return {v[0], v[1], v[2]}; }

glm::vec2 project(const KCamera& c, glm::vec3 p) {
  const glm::vec3 d = p - load(c.origin);
  const float z = glm::dot(d, load(c.forward));
  return {(glm::dot(d, load(c.right)) / (z * c.tan_half_fov_x) + 1.0f) * 0.5f * float(c.width),
          (1.0f - glm::dot(d, load(c.up)) / (z * c.tan_half_fov_y)) * 0.5f * float(c.height)};
}

// The world point at a pixel centre at the given depth along the camera's forward axis.
glm::vec3 point_at(const KCamera& c, float px, float py, float depth) {
  const float sx = (2.0f * px / float(c.width) - 1.0f) * c.tan_half_fov_x;
  const float sy = (1.0f - 2.0f * py / float(c.height)) * c.tan_half_fov_y;
  return load(c.origin) + depth * (load(c.forward) + sx * load(c.right) + sy * load(c.up));
}

}  // namespace

class SkinnedMotion : public ::testing::TestWithParam<std::string> {};

TEST_P(SkinnedMotion, FollowsThePreviousPoseOfTheJoints) {
  const std::string device = GetParam();
  if (!tracer_runs_here(device)) GTEST_SKIP() << "needs the " << device << " tracer here";
  scene::Scene map = load_test_map();
  scene::RenderWorld world(map);
  const int handle = world.FindEntityDef("walker_1");
  ASSERT_GE(handle, 0);
  ASSERT_TRUE(map.entities[size_t(handle)].anim);
  const int w = 64, h = 48;
  core::WorldSyncOptions options;
  options.width = w, options.height = h;
  core::WorldSync sync(world, options);
  world.TakeChanges();
  scene::RenderEntity def = *world.EntityDef(handle);
  ASSERT_NEAR(def.axis[2].z, 1.0f, 1e-4f) << "the test moves the joints along the walker's up axis";
  const glm::vec3 eye = def.origin + def.axis[0] * 110.0f + glm::vec3(0.0f, 0.0f, 48.0f);
  const glm::vec3 to = def.origin + glm::vec3(0.0f, 0.0f, 32.0f) - eye;
  const KCamera camera = core::make_camera(
      eye, {glm::degrees(std::atan2(to.y, to.x)), glm::degrees(std::atan2(-to.z, std::hypot(to.x, to.y)))}, 70.0f, w, h);

  auto tracer = make_test_tracer(device);
  tracer->apply(commit::CommitBuffer::full(sync.snapshot(), 0));
  def.joints = scene::anim_pose(*map.entities[size_t(handle)].anim, 300);
  world.UpdateEntityDef(handle, def);
  tracer->apply(sync.sync(world.TakeChanges(), 1));
  const float lift = 5.0f;
  for (auto& joint : def.joints) joint.position.z += lift;
  world.UpdateEntityDef(handle, def);
  const commit::CommitBuffer lifted = sync.sync(world.TakeChanges(), 2);
  ASSERT_EQ(lifted.skin_joints().size(), 1u);
  tracer->apply(lifted);
  const core::GBuffer g = render_aux_band(*tracer, camera, camera);

  const uint32_t walker = uint32_t(handle) + 1u;  // the id plane holds the entity handle + 1 (aux_outputs.h)
  int checked = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = size_t(y) * w + x;
      if (g.id[p] != walker || !(g.depth[p] > 0.0f)) continue;
      const glm::vec3 point = point_at(camera, x + 0.5f, y + 0.5f, g.depth[p]);
      const glm::vec2 was = project(camera, point - glm::vec3(0.0f, 0.0f, lift));
      ASSERT_NEAR(g.motion[2 * p], was.x - (x + 0.5f), 0.02f) << device << " at " << x << "," << y;
      ASSERT_NEAR(g.motion[2 * p + 1], was.y - (y + 0.5f), 0.02f) << device << " at " << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 100) << "pixels of the walker checked";
}

INSTANTIATE_TEST_SUITE_P(Devices, SkinnedMotion, ::testing::Values("embree", "opencl", "cuda"),
                         [](const auto& info) { return info.param; });
