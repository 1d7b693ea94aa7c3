// The test map's animated materials on every tracer: WorldSync evaluates the registers at the frame's
// time and sends only the materials and lights that changed (scrolling pillars, the turning vent grille,
// the pulsing light strip, the flickering light); Embree and each other tracer, fed the same commits,
// draw the same image (the bound of agreement_test.cpp) while the time visibly changes it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>

#include "cohort/core/view.h"
#include "cohort/core/world_sync.h"
#include "cohort/scene/map_loader.h"
#include "cohort/scene/render_world.h"
#include "test_scenes.h"
#include "test_tracers.h"

using namespace cohort;
using namespace cohort::test;

namespace {

struct View {
  const char* name;
  glm::vec3 eye;
  float yaw, pitch;
};

// The hall's west end (the vent grille turning on the wall, two scrolling pillars) and the corridor
// behind the door (the pulsing strip on its ceiling, lit by the flickering light).
const View kViews[] = {
    {"hall_west", {300, 192, 80}, 180.0f, 0.0f},
    {"corridor", {556, 192, 70}, 0.0f, -20.0f},
};

}  // namespace

class AnimatedMaterialsAgreement : public ::testing::TestWithParam<std::string> {};

TEST_P(AnimatedMaterialsAgreement, TestMapAtLaterTimesMatchesEmbree) {
  const std::string device = GetParam();
  if (!tracer_runs_here("embree") || !tracer_runs_here(device)) GTEST_SKIP() << "needs the Embree and " << device << " tracers here";
  scene::Scene map = load_test_map();
  scene::RenderWorld world(map);
  const int w = 64, h = 40;
  core::WorldSyncOptions options;
  options.width = w, options.height = h;
  core::WorldSync sync(world, options);
  world.TakeChanges();
  const KFrameParams params = testmap_agreement_params(h);

  auto embree = make_test_tracer("embree");
  auto other = make_test_tracer(device);
  embree->apply(commit::CommitBuffer::full(sync.snapshot(), 0));
  other->apply(commit::CommitBuffer::full(sync.snapshot(), 0));
  std::vector<core::FrameBuffer> at_start;
  for (const View& v : kViews)
    at_start.push_back(render_frame(*embree, core::make_camera(v.eye, {v.yaw, v.pitch}, 90.0f, w, h), params));

  uint64_t frame = 1;
  for (double seconds : {0.7, 1.9}) {
    sync.set_time(seconds);
    const commit::CommitBuffer records = sync.sync(world.TakeChanges(), frame++);
    EXPECT_GE(records.materials().size(), 3u) << "the pillars, the vent and the strip change at " << seconds << " s";
    EXPECT_GE(records.lights().size(), 1u) << "the flickering light changes at " << seconds << " s";
    embree->apply(records);
    other->apply(records);
    for (size_t i = 0; i < std::size(kViews); ++i) {
      const View& v = kViews[i];
      const KCamera camera = core::make_camera(v.eye, {v.yaw, v.pitch}, 90.0f, w, h);
      const core::FrameBuffer a = render_frame(*embree, camera, params);
      const core::FrameBuffer b = render_frame(*other, camera, params);
      double mean = 0.0, changed_mean = 0.0;
      const double error = rgb_rmse(a, b, &mean);
      const double changed = rgb_rmse(a, at_start[i], &changed_mean);
      std::cout << v.name << " at " << seconds << " s: RMSE embree/" << device << " " << error << ", against time 0 "
                << changed << ", mean " << mean << "\n";
      EXPECT_GT(mean, 0.01) << v.name;
      EXPECT_LT(error, 0.005 * mean) << v.name << " at " << seconds << " s";
      EXPECT_GT(changed, 10.0 * error) << v.name << ": the time should change the image far more than the tracers differ";
      if (const char* dir = std::getenv("COHORT_TEST_IMAGES")) {
        const std::string stem = std::string(dir) + "/animated_" + v.name + "_" + std::to_string(int(seconds * 1000));
        write_preview(stem + "_embree.png", a);
        write_preview(stem + "_" + device + ".png", b);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Devices, AnimatedMaterialsAgreement, ::testing::Values("opencl", "cuda"),
                         [](const auto& info) { return info.param; });
