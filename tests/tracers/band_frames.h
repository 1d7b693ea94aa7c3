// Frames rendered band by band and held to the same bits: the wavefronts against the renderers they stand
// in for (opencl_wavefront_test.cpp: the megakernel; embree_wavefront_test.cpp: the path-by-path tiles),
// with the views both look through.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "cohort/core/band_buffer.h"
#include "cohort/core/tracer.h"
#include "cohort/core/view.h"
#include "test_scenes.h"

namespace cohort::test {

struct View {
  std::shared_ptr<commit::TracerScene> scene;
  KCamera camera;
};

inline View room_view(int w, int h) {
  static const auto room = std::make_shared<commit::TracerScene>(core::compile_scene(test_room()).tracer_scene);
  return {room, test_room_camera(w, h)};
}

// The generated test map (what its scene pack holds) and where its player starts.
struct TestMapScene {
  std::shared_ptr<commit::TracerScene> scene;
  glm::vec3 eye;
  float yaw;
};
inline const TestMapScene& test_map_scene() {
  static const TestMapScene map = [] {
    const scene::Scene m = load_test_map();
    return TestMapScene{std::make_shared<commit::TracerScene>(core::compile_scene(m).tracer_scene), core::player_eye(m),
                        m.player_yaw};
  }();
  return map;
}

// The test map from the player start at eye height.
inline View map_view(int w, int h) {
  const TestMapScene& map = test_map_scene();
  return {map.scene, core::make_camera(map.eye, {map.yaw, 0.0f}, core::kDefaultFovX, w, h)};
}

// Where the generated test map is looked at from (tools/gen_testmap.py's README names the areas).
enum class MapSpot {
  player_start,  // the hall: pillars, table, crates, a blood decal
  atrium,        // from the corridor's end: the glass screen, the grate under the skylight, the stairwell's fog
  gallery,       // the glass case on its pedestal, the sky court's noSelfShadow shrub behind
};

inline View map_view(MapSpot spot, int w, int h) {
  const TestMapScene& map = test_map_scene();
  switch (spot) {
    case MapSpot::atrium:
      return {map.scene, core::make_camera({740, 192, 90}, {0.0f, -12.0f}, core::kDefaultFovX, w, h)};
    case MapSpot::gallery:
      return {map.scene, core::make_camera({1440, 160, 170}, {20.0f, 12.0f}, core::kDefaultFovX, w, h)};
    case MapSpot::player_start:
      break;
  }
  return map_view(w, h);
}

// A floor of point and projected lights under an emissive panel (two emissive triangles), seen from above.
inline View many_lights_view(int point_lights, int projected_lights, int w, int h) {
  scene::Scene floor = many_lights_floor_under_a_panel(point_lights, projected_lights);
  return {std::make_shared<commit::TracerScene>(core::compile_scene(floor).tracer_scene),
          camera_looking_down({0, 0, 1400}, 0.7f, w, h)};
}

// What a wavefront case renders with (each a field of the tests' SceneCase): frame 5, the firefly clamp,
// soft shadows and shadow roulette on, the sparse pattern's phase 3, one light sample (none with `every`).
inline KFrameParams wave_case_params(uint32_t mode, uint32_t spp, uint32_t bounces, int height, float rr_start,
                                     kuint aux, uint32_t path_pixels, uint32_t light_sampling) {
  KFrameParams params = frame_params(mode, spp, bounces, height);
  params.rr_start = rr_start;
  params.frame_index = 5;
  params.firefly_clamp = 5.0f;
  params.soft_shadow_scale = 0.2f;
  params.shadow_rr = 0.03f;
  params.aux_outputs = aux;
  params.path_pixels = path_pixels;
  params.path_phase = 3;
  params.light_sampling = light_sampling;
  params.light_samples = light_sampling == K_LIGHTS_EVERY ? 0u : 1u;
  return params;
}

struct BandFrame {
  core::BandBuffer frame;
  std::vector<float> row_work;  // the bands' rays per row, band after band
  double device_ms = 0.0;       // the bands' BandResult::device_ms, summed
};

// The frame through `camera` rendered band by band by `tracer` on the scene it has (cuts: the bands' first
// rows, then the height), with its aux planes when params.aux_outputs asks for them.
inline BandFrame render_bands_of(core::Tracer& tracer, const KCamera& camera, const KFrameParams& params,
                                 const std::vector<int>& cuts) {
  BandFrame out;
  out.frame.resize(int(camera.width), int(camera.height), core::BandFormat::rgba32f);
  out.frame.enable_aux(params.aux_outputs != 0u);
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    core::BandJob job;
    job.params = params;
    job.params.row_begin = kuint(cuts[i]);
    job.params.row_end = kuint(cuts[i + 1]);
    job.camera = camera;
    const core::BandResult result = tracer.render_band(job, out.frame);
    out.row_work.insert(out.row_work.end(), result.row_work.begin(), result.row_work.end());
    out.device_ms += result.device_ms;
  }
  return out;
}

// The same with the view's scene applied first.
inline BandFrame render_in_bands(core::Tracer& tracer, const View& view, const KFrameParams& params,
                                 const std::vector<int>& cuts) {
  tracer.apply(commit::CommitBuffer::full(view.scene, 1));
  return render_bands_of(tracer, view.camera, params, cuts);
}

// The floats of a and b (RGBA32F bands of one size) whose bits differ.
inline size_t differing_floats(core::BandBuffer& a, core::BandBuffer& b) {
  const float* fa = static_cast<const float*>(a.data());
  const float* fb = static_cast<const float*>(b.data());
  size_t n = 0;
  for (size_t i = 0; i < a.bytes() / sizeof(float); ++i) n += std::memcmp(fa + i, fb + i, sizeof(float)) != 0;
  return n;
}

// `frame` (finite, not black) is `reference` bit for bit: every float, the aux texels where the frame has
// them (aux), and the rays counted per row of its `height` rows (row_work: the bands' counts, band after band).
inline void expect_same_band_frame(core::BandBuffer& reference, const std::vector<float>& reference_row_work,
                                   core::BandBuffer& frame, const std::vector<float>& row_work, bool aux, int height,
                                   const std::string& reference_name) {
  double sum = 0.0;
  const float* f = static_cast<const float*>(frame.data());
  for (size_t i = 0; i < frame.bytes() / sizeof(float); ++i) {
    ASSERT_TRUE(std::isfinite(f[i])) << "float " << i;
    sum += f[i];
  }
  EXPECT_GT(sum, 0.0) << "the frame shows something";
  EXPECT_EQ(differing_floats(reference, frame), 0u) << "floats that differ from " << reference_name;
  if (aux) {
    ASSERT_EQ(reference.aux_bytes(), frame.aux_bytes());
    EXPECT_EQ(std::memcmp(reference.aux_data(), frame.aux_data(), reference.aux_bytes()), 0) << "the aux planes differ";
  }
  ASSERT_EQ(row_work.size(), size_t(height)) << "every band reports its row ray counts";
  EXPECT_EQ(row_work, reference_row_work) << "rays counted per row";
}

}  // namespace cohort::test
