#include <gtest/gtest.h>

#include "cohort/scene/image_decode.h"
#include "cohort/scene/image_library.h"
#include "cohort/scene/image_ops.h"
#include "test_files.h"

using namespace cohort::scene;
using cohort::scene::test::data_dir;
using cohort::scene::test::read_text;

namespace {

const uint8_t* texel(const Image& image, int x, int y) { return &image.rgba[(static_cast<size_t>(y) * image.width + x) * 4]; }

std::string tga_header(int type, int w, int h, int bits, int descriptor) {
  std::string hdr(18, '\0');
  hdr[2] = static_cast<char>(type);
  hdr[12] = static_cast<char>(w & 255);
  hdr[13] = static_cast<char>(w >> 8);
  hdr[14] = static_cast<char>(h & 255);
  hdr[15] = static_cast<char>(h >> 8);
  hdr[16] = static_cast<char>(bits);
  hdr[17] = static_cast<char>(descriptor);
  return hdr;
}

}  // namespace

TEST(TgaReader, BottomUpRowsComeOutTopFirst) {
  std::string error;
  auto image = decode_tga(read_text(data_dir() / "base/textures/test/floor.tga"), error);
  ASSERT_TRUE(image) << error;
  EXPECT_EQ(texel(*image, 0, 0)[0], 255);   // red at the top left
  EXPECT_EQ(texel(*image, 1, 0)[1], 255);   // green at the top right
  EXPECT_EQ(texel(*image, 0, 1)[2], 255);   // blue at the bottom left
}

TEST(TgaReader, RunLengthGreyAndAlpha) {
  std::string error;
  auto wall = decode_tga(read_text(data_dir() / "base/textures/test/wall.tga"), error);
  ASSERT_TRUE(wall) << error;
  EXPECT_EQ(texel(*wall, 1, 0)[2], 60);
  // A run packet of three grey texels.
  std::string grey = tga_header(11, 3, 1, 8, 0x20) + std::string("\x82\x7f", 2);
  auto g = decode_tga(grey, error);
  ASSERT_TRUE(g) << error;
  EXPECT_EQ(texel(*g, 2, 0)[1], 0x7f);
  auto grate = decode_tga(read_text(data_dir() / "base/textures/test/grate.tga"), error);
  ASSERT_TRUE(grate);
  EXPECT_EQ(texel(*grate, 1, 0)[3], 0);
  EXPECT_EQ(texel(*grate, 0, 0)[3], 255);
}

TEST(TgaReader, DamagedFilesAreErrorsNotCrashes) {
  std::string error;
  EXPECT_FALSE(decode_tga("short", error));
  EXPECT_FALSE(decode_tga(tga_header(2, 4, 4, 24, 0) + "abc", error));
  EXPECT_NE(error.find("truncated"), std::string::npos);
  EXPECT_FALSE(decode_tga(tga_header(2, 0, 4, 24, 0), error));
  EXPECT_FALSE(decode_tga(tga_header(1, 4, 4, 8, 0), error));        // colour-mapped
  EXPECT_FALSE(decode_tga(tga_header(10, 60000, 60000, 32, 0) + "\xff\x01\x02\x03\x04", error));  // too large
  EXPECT_FALSE(decode_tga(tga_header(10, 4, 4, 24, 0) + "\x81\x01\x02\x03", error));  // runs stop early
}

TEST(ImageDecode, RxgbHeaderIsRecognised) {
  std::string dds(128, '\0');
  dds.replace(0, 4, "DDS ");
  dds.replace(84, 4, "RXGB");
  EXPECT_TRUE(is_rxgb_dds(dds));
  dds.replace(84, 4, "DXT5");
  EXPECT_FALSE(is_rxgb_dds(dds));
}

TEST(ImageOps, ProgramsChangeTexelsAsTheEngineDoes) {
  Image grey = solid_image("g", 90, 120, 150, 200);
  EXPECT_EQ(texel(make_alpha(grey), 0, 0)[3], 120);
  EXPECT_EQ(texel(make_alpha(grey), 0, 0)[0], 255);
  EXPECT_EQ(texel(make_intensity(grey), 0, 0)[3], 90);
  EXPECT_EQ(texel(invert_alpha(grey), 0, 0)[3], 55);
  EXPECT_EQ(texel(invert_color(grey), 0, 0)[0], 165);
  float half[4] = {0.5f, 1, 1, 1};
  EXPECT_EQ(texel(scale_channels(grey, half), 0, 0)[0], 45);
  Image flat = solid_image("f", 128, 128, 255, 255);
  Image tilted = solid_image("t", 255, 128, 128, 255);  // +x
  Image combined = add_normals(flat, tilted);
  const uint8_t* sum = texel(combined, 0, 0);
  EXPECT_GT(sum[0], 200);  // leans to +x
  EXPECT_LT(sum[2], 200);
  EXPECT_EQ(texel(add_images(grey, grey), 0, 0)[2], 255);  // clamped
}

TEST(ImageLibrary, MissingImagesGetRolePlaceholdersAndOneWarningEach) {
  Vfs vfs;
  vfs.add_search_path(data_dir() / "base");
  std::vector<Image> images;
  std::vector<std::string> warnings;
  ImageLibrary library(vfs, images, warnings);
  ImageProgram missing;
  missing.path = "textures/test/nothing_here";
  int color = library.get(missing, ImageRole::Color, "material m");
  int again = library.get(missing, ImageRole::Color, "material m");
  int normal = library.get(missing, ImageRole::Normal, "material m");
  EXPECT_EQ(color, again);
  EXPECT_TRUE(images[static_cast<size_t>(color)].is_placeholder);
  EXPECT_EQ(images[static_cast<size_t>(color)].width, 8);
  EXPECT_EQ(texel(images[static_cast<size_t>(normal)], 0, 0)[2], 255);
  EXPECT_TRUE(images[static_cast<size_t>(normal)].is_normal_map);
  EXPECT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("material m: image 'textures/test/nothing_here'"), std::string::npos);
  EXPECT_EQ(library.placeholder_count(), 2);

  ImageProgram by_bare_name;   // no extension: found as .tga like the engine does
  by_bare_name.path = "TEXTURES/test/Floor";
  int floor = library.get(by_bare_name, ImageRole::Color, "material m");
  EXPECT_FALSE(images[static_cast<size_t>(floor)].is_placeholder);
  EXPECT_EQ(images[static_cast<size_t>(floor)].width, 2);
}

#ifdef COHORT_HAVE_OIIO
#include <OpenImageIO/imageio.h>

TEST(ImageLibrary, PngThroughOpenImageIOFoundByBareName) {
  namespace fs = std::filesystem;
  fs::path base = fs::path(COHORT_BINARY_DIR) / "test_tmp" / "png_base";
  fs::remove_all(base);
  fs::create_directories(base / "textures");
  const uint8_t pixels[] = {10, 20, 30, 255, 200, 100, 50, 255};
  auto out = OIIO::ImageOutput::create("png");
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(2, 1, 4, OIIO::TypeDesc::UINT8);
  ASSERT_TRUE(out->open((base / "textures/pic.png").string(), spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels));
  out->close();

  Vfs vfs;
  vfs.add_search_path(base);
  std::vector<Image> images;
  std::vector<std::string> warnings;
  ImageLibrary library(vfs, images, warnings);
  ImageProgram program;
  program.path = "textures/pic.tga";   // materials name .tga; the engine falls back to other formats
  const Image& image = images[static_cast<size_t>(library.get(program, ImageRole::Color, "m"))];
  EXPECT_TRUE(warnings.empty()) << ::testing::PrintToString(warnings);
  ASSERT_EQ(image.width, 2);
  EXPECT_EQ(texel(image, 1, 0)[0], 200);
  EXPECT_EQ(texel(image, 0, 0)[2], 30);
}
#endif
