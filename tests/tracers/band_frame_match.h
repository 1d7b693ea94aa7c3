// Two renders of one frame, band by band, held to the same bits: the wavefronts against the renderers they
// stand in for (opencl_wavefront_test.cpp: the megakernel; embree_wavefront_test.cpp: the path-by-path tiles).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cohort/core/band_buffer.h"

namespace cohort::test {

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
