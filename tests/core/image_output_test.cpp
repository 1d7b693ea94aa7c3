#include <filesystem>

#include <gtest/gtest.h>

#include "cohort/core/image_output.h"

using namespace cohort::core;

TEST(ImageOutput, PfmRoundTripKeepsHdrValuesAndRowOrder) {
  FrameBuffer frame;
  frame.resize(3, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c) frame.row(y)[x * 4 + c] = float(100 * y + 10 * x + c) + 0.25f;
  auto file = std::filesystem::temp_directory_path() / "cohort_roundtrip.pfm";
  write_hdr_image(file, frame);
  FrameBuffer back = read_pfm(file);
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  EXPECT_FLOAT_EQ(back.row(1)[2 * 4 + 1], 121.25f);
  EXPECT_FLOAT_EQ(back.row(0)[0], 0.25f);
  std::filesystem::remove(file);
}

TEST(ImageOutput, PpmHasHeaderAndPixels) {
  std::vector<uint8_t> rgba = {255, 0, 0, 255, 0, 255, 0, 255};
  auto file = std::filesystem::temp_directory_path() / "cohort_two.ppm";
  write_ldr_image(file, 2, 1, rgba);
  EXPECT_EQ(std::filesystem::file_size(file), std::string("P6\n2 1\n255\n").size() + 6);
  std::filesystem::remove(file);
}

TEST(ImageOutput, MismatchedBufferIsRejected) {
  EXPECT_THROW(write_ldr_image("x.ppm", 4, 4, std::vector<uint8_t>(3)), std::invalid_argument);
}
