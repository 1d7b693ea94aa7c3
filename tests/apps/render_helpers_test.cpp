#include <sstream>

#include <gtest/gtest.h>

#include "camera_path.h"
#include "convergence_choice.h"
#include "workload_choice.h"
#include "progress_bar.h"

namespace cohort::app {
namespace {

TEST(WorkloadChoice, CpuOnlySessionsHoldThirtyFpsByDefault) {
  EXPECT_EQ(resolve_target_fps(-1, false, false), kCpuTargetFps);
  EXPECT_EQ(resolve_target_fps(-1, true, false), 0) << "a GPU session keeps the user's spp and scale";
  EXPECT_EQ(resolve_target_fps(-1, false, true), 0) << "--spp or --scale given: they stand";
  EXPECT_EQ(resolve_target_fps(0, false, false), 0) << "0 turns the target off";
  EXPECT_EQ(resolve_target_fps(60, true, true), 60);
  // A frame four times too slow at full scale and 1 spp: the scaler lowers the scale, not below 0.25.
  core::WorkloadScaler scaler(workload_options(30), core::WorkloadSetting{1, 1.0});
  core::WorkloadSetting s = scaler.current();
  for (int frame = 0; frame < 40; ++frame) s = scaler.update(4.0 * 33.3 * s.render_scale * s.render_scale);
  EXPECT_EQ(s.spp, 1);
  EXPECT_NEAR(s.render_scale, 0.5, 0.06) << "frame time ~ scale^2: half the scale fits";
  EXPECT_GE(s.render_scale, 0.25);
}

TEST(ConvergenceChoice, AutoReprojectsUnlessGpuTracersWouldWaitForTheHost) {
  EXPECT_EQ(resolve_convergence("auto", false, "host"), "reproject");
  EXPECT_EQ(resolve_convergence("auto", true, "host"), "brigade") << "an OpenCL GPU with the host's reprojection";
  EXPECT_EQ(resolve_convergence("auto", true, "cuda:0"), "reproject") << "the post-processing on the GPU";
  EXPECT_EQ(resolve_convergence("reproject", true, "host"), "reproject") << "an explicit choice stands";
  EXPECT_EQ(resolve_convergence("brigade", false, "cuda:1"), "brigade");
}

TEST(CameraPath, ParsesNamesAndRejectsUnknownOnes) {
  EXPECT_EQ(parse_camera_path("spin").kind, CameraPath::Kind::spin);
  EXPECT_EQ(parse_camera_path("orbit-fast").kind, CameraPath::Kind::orbit);
  EXPECT_GT(parse_camera_path("orbit-fast").degrees_per_frame, parse_camera_path("orbit-slow").degrees_per_frame);
  EXPECT_THROW(parse_camera_path("wobble"), std::invalid_argument);
  EXPECT_THROW(parse_camera_path("spin-medium"), std::invalid_argument);
  try {
    parse_camera_path("zoom");
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("orbit-fast"), std::string::npos) << "the message lists the names";
  }
}

TEST(CameraPath, OptionCheckPassesPathsAndGivesTheParsersMessageOtherwise) {
  EXPECT_EQ(camera_path_error("orbit-fast"), "");
  EXPECT_EQ(camera_path_error("spin"), "");
  std::string parser_message;
  try {
    parse_camera_path("spin-medium");
  } catch (const std::invalid_argument& e) {
    parser_message = e.what();
  }
  EXPECT_FALSE(parser_message.empty());
  EXPECT_EQ(camera_path_error("spin-medium"), parser_message);
}

TEST(CameraPath, SpinStaysAndTurnsOrbitCirclesFacingTheStart) {
  const glm::vec3 eye(100, 200, 68);
  const CameraPath spin = parse_camera_path("spin-slow");
  const CameraPose p0 = camera_path_pose(spin, eye, 30.0f, 0), p10 = camera_path_pose(spin, eye, 30.0f, 10);
  EXPECT_EQ(p0.origin, eye);
  EXPECT_EQ(p10.origin, eye);
  EXPECT_FLOAT_EQ(p10.yaw - p0.yaw, 10 * spin.degrees_per_frame);

  const CameraPath orbit = parse_camera_path("orbit");
  for (int f : {0, 7, 45}) {
    const CameraPose p = camera_path_pose(orbit, eye, 30.0f, f);
    EXPECT_NEAR(glm::length(p.origin - eye), orbit.orbit_radius, 1e-3f);
    const glm::vec3 look(std::cos(glm::radians(p.yaw)), std::sin(glm::radians(p.yaw)), 0.0f);
    EXPECT_NEAR(glm::dot(glm::normalize(eye - p.origin), look), 1.0f, 1e-4f) << "frame " << f;
  }
}

TEST(ProgressBar, ReportsFramesRateAndEta) {
  std::ostringstream out;
  ProgressBar bar(4, out, false);
  EXPECT_NE(bar.line().find("0/4 frames"), std::string::npos);
  bar.frame_done(10.0);
  bar.frame_done(30.0);
  EXPECT_NE(bar.line().find("2/4 frames"), std::string::npos) << bar.line();
  EXPECT_NE(bar.line().find("20.0 ms/frame"), std::string::npos) << bar.line();
  EXPECT_NE(bar.line().find("ETA 0.0 s"), std::string::npos) << bar.line();  // 2 x 20 ms = 0.04 s
  bar.frame_done(20.0);
  bar.frame_done(20.0);
  bar.finish();
  EXPECT_NE(out.str().find("[########################] 4/4 frames"), std::string::npos) << out.str();
}

}  // namespace
}  // namespace cohort::app
