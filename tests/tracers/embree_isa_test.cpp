// The Embree tracer's shading code is built twice, for any x86-64 and for x86-64-v3 (AVX2, FMA), and
// picks one at run time: both must draw the same image (FMA contraction moves only the last bits).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "test_scenes.h"
#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_tracer.h"
#endif

namespace cohort::test {

#ifdef COHORT_HAVE_EMBREE
TEST(EmbreeIsa, BaselineAndX86_64V3BuildsDrawTheSameImage) {
  tracers::EmbreeTracer tracer;
  if (!tracer.prefer_x86_64_v3(true)) GTEST_SKIP() << "no x86-64-v3 build or CPU here";
  const scene::Scene room = test_room();
  const KCamera camera = test_room_camera(64, 48);
  KFrameParams params = frame_params(K_MODE_PATH, 4, 1, 48);
  params.frame_index = 3;
  const core::FrameBuffer v3 = render(tracer, room, camera, params);
  ASSERT_FALSE(tracer.prefer_x86_64_v3(false));
  const core::FrameBuffer baseline = render(tracer, room, camera, params);
  ASSERT_EQ(v3.rgba.size(), baseline.rgba.size());
  double sum = 0.0, squared_error = 0.0;
  for (size_t i = 0; i < v3.rgba.size(); ++i) {
    sum += baseline.rgba[i];
    squared_error += (v3.rgba[i] - baseline.rgba[i]) * double(v3.rgba[i] - baseline.rgba[i]);
  }
  const double mean = sum / double(v3.rgba.size());
  const double error = std::sqrt(squared_error / double(v3.rgba.size()));
  EXPECT_GT(mean, 0.01) << "the room should be lit";
  EXPECT_LT(error, 1e-3 * mean) << "RMSE " << error << " vs mean " << mean;
  std::cout << "x86-64-v3 vs baseline: RMSE " << error << ", mean " << mean << "\n";
}
#endif

}  // namespace cohort::test
