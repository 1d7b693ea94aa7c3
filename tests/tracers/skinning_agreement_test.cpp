// The walking character on every tracer: the test map's walker is posed through commits carrying only its
// joints; the Embree tracer skins it on the host, OpenCL and CUDA on their devices, and their images of it
// agree (the same bound as agreement_test.cpp), while the pose visibly changes the image.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>

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

}  // namespace

class SkinningAgreement : public ::testing::TestWithParam<std::string> {};

TEST_P(SkinningAgreement, WalkerPosedMatchesEmbree) {
  const std::string device = GetParam();
  if (!tracer_runs_here("embree") || !tracer_runs_here(device)) GTEST_SKIP() << "needs the Embree and " << device << " tracers here";
  scene::Scene map = load_test_map();
  scene::RenderWorld world(map);
  const int handle = world.FindEntityDef("walker_1");
  ASSERT_GE(handle, 0);
  ASSERT_TRUE(map.entities[size_t(handle)].anim) << "the walker's animation should load with the map";
  const scene::Md5Anim& anim = *map.entities[size_t(handle)].anim;
  const int w = 64, h = 48;
  core::WorldSyncOptions options;
  options.width = w, options.height = h;
  core::WorldSync sync(world, options);
  world.TakeChanges();
  const scene::RenderEntity start = *world.EntityDef(handle);
  // Looking at the walker from in front of it, slightly down.
  const glm::vec3 eye = start.origin + start.axis[0] * 110.0f + glm::vec3(0.0f, 0.0f, 48.0f);
  const glm::vec3 to = start.origin + glm::vec3(0.0f, 0.0f, 32.0f) - eye;
  const float yaw = glm::degrees(std::atan2(to.y, to.x));
  const float pitch = glm::degrees(std::atan2(-to.z, std::hypot(to.x, to.y)));
  const KCamera camera = core::make_camera(eye, {yaw, pitch}, 70.0f, w, h);
  const KFrameParams params = testmap_agreement_params(h);

  auto embree = make_test_tracer("embree");
  auto opencl = make_test_tracer(device);
  embree->apply(commit::CommitBuffer::full(sync.snapshot(), 0));
  opencl->apply(commit::CommitBuffer::full(sync.snapshot(), 0));
  const core::FrameBuffer bind = render_frame(*embree, camera, params);

  uint64_t frame = 1;
  for (int time_ms : {300, 700}) {
    scene::RenderEntity def = start;
    def.joints = scene::anim_pose(anim, time_ms);
    def.origin += start.axis[0] * (float(time_ms) * 0.02f);
    world.UpdateEntityDef(handle, def);
    const commit::CommitBuffer records = sync.sync(world.TakeChanges(), frame++);
    ASSERT_EQ(records.skin_joints().size(), 1u);
    embree->apply(records);
    opencl->apply(records);
    const core::FrameBuffer a = render_frame(*embree, camera, params);
    const core::FrameBuffer b = render_frame(*opencl, camera, params);
    double mean = 0.0, moved_mean = 0.0;
    const double error = rgb_rmse(a, b, &mean);
    const double moved = rgb_rmse(a, bind, &moved_mean);
    std::cout << "walker at " << time_ms << " ms: RMSE embree/" << device << " " << error << ", against the bind pose " << moved
              << ", mean " << mean << "\n";
    EXPECT_GT(mean, 0.01);
    EXPECT_LT(error, 0.005 * mean) << "at " << time_ms << " ms";
    EXPECT_GT(moved, 10.0 * error) << "the pose should change the image far more than the tracers differ";
    if (const char* dir = std::getenv("COHORT_TEST_IMAGES")) {
      write_preview(std::string(dir) + "/walker_" + std::to_string(time_ms) + "_embree.png", a);
      write_preview(std::string(dir) + "/walker_" + std::to_string(time_ms) + "_" + device + ".png", b);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, SkinningAgreement, ::testing::Values("opencl", "cuda"),
                         [](const auto& info) { return info.param; });
