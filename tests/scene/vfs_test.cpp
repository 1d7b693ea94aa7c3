#include <gtest/gtest.h>
#include <zip.h>

#include <fstream>

#include "cohort/scene/vfs.h"

using namespace cohort::scene;
namespace fs = std::filesystem;

namespace {

void write_file(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// Builds a .pk4 with libzip from name -> contents pairs.
void write_pk4(const fs::path& path, const std::vector<std::pair<std::string, std::string>>& files) {
  int error = 0;
  zip_t* zip = zip_open(path.string().c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  ASSERT_NE(zip, nullptr);
  for (const auto& [name, text] : files) {
    char* copy = static_cast<char*>(malloc(text.size() + 1));
    memcpy(copy, text.data(), text.size());
    zip_source_t* source = zip_source_buffer(zip, copy, text.size(), 1);
    ASSERT_NE(source, nullptr);
    ASSERT_GE(zip_file_add(zip, name.c_str(), source, ZIP_FL_OVERWRITE), 0);
  }
  ASSERT_EQ(zip_close(zip), 0);
}

class VfsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root = fs::path(COHORT_BINARY_DIR) / "test_tmp" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(root);
    fs::create_directories(root / "base");
  }
  fs::path root;
};

}  // namespace

TEST_F(VfsTest, LaterArchivesOverrideEarlierAndLooseFilesOverrideArchives) {
  write_pk4(root / "base" / "pak000.pk4", {{"materials/a.mtr", "from pak000"},
                                           {"textures/Base/Floor.tga", "floor from pak000"},
                                           {"maps/m.map", "map from pak000"}});
  write_pk4(root / "base" / "pak001.pk4", {{"materials/a.mtr", "from pak001"}, {"materials/b.mtr", "b"}});
  write_file(root / "base" / "maps" / "m.map", "loose map");

  Vfs vfs;
  vfs.add_search_path(root / "base");
  EXPECT_EQ(vfs.read("materials/a.mtr").value(), "from pak001");
  EXPECT_EQ(vfs.read("maps/m.map").value(), "loose map");
  EXPECT_EQ(vfs.read("TEXTURES\\base\\floor.TGA").value(), "floor from pak000");  // case and separators
  EXPECT_FALSE(vfs.read("textures/missing.tga").has_value());
  EXPECT_FALSE(vfs.exists("materials/c.mtr"));
  EXPECT_NE(vfs.describe("materials/a.mtr").find("pak001.pk4:materials/a.mtr"), std::string::npos);

  auto mtrs = vfs.list("materials", ".mtr");
  ASSERT_EQ(mtrs.size(), 2u);
  EXPECT_EQ(mtrs[0], "materials/a.mtr");
  EXPECT_EQ(mtrs[1], "materials/b.mtr");
}

TEST_F(VfsTest, LaterSearchPathOverridesEarlier) {
  write_file(root / "base" / "materials" / "a.mtr", "base");
  write_file(root / "mod" / "materials" / "a.mtr", "mod");
  Vfs vfs;
  vfs.add_search_path(root / "base");
  vfs.add_search_path(root / "mod");
  EXPECT_EQ(vfs.read("materials/a.mtr").value(), "mod");
  EXPECT_EQ(vfs.search_paths().size(), 2u);
}

TEST_F(VfsTest, MissingFolderAndDamagedArchiveAreErrors) {
  Vfs vfs;
  EXPECT_THROW(vfs.add_search_path(root / "nowhere"), std::runtime_error);
  write_file(root / "bad" / "pak000.pk4", "this is not a zip file");
  EXPECT_THROW(vfs.add_search_path(root / "bad"), std::runtime_error);
}
