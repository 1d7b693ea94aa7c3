// Replays the fuzzers' seed corpus (and any crash inputs saved beside it) through every parser in
// the ordinary build, so that inputs which once crashed keep being checked without clang.
#include <gtest/gtest.h>

#include <filesystem>

#include "../../scene/fuzz/fuzz_targets.h"
#include "test_files.h"

namespace fs = std::filesystem;
using cohort::scene::test::read_text;

namespace {

int replay(const std::string& corpus, void (*target)(const uint8_t*, size_t), const char* extra_dir = nullptr,
           const char* extra_extension = nullptr) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(fs::path(COHORT_SOURCE_DIR) / "scene/fuzz/corpus" / corpus))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::error_code ec;
  fs::path extra = extra_dir ? fs::path(COHORT_SOURCE_DIR) / extra_dir : fs::path();
  if (extra_dir && fs::is_directory(extra, ec))   // the generated test map, when present
    for (const auto& entry : fs::directory_iterator(extra))
      if (entry.path().extension() == extra_extension) files.push_back(entry.path());
  int count = 0;
  for (const fs::path& file : files) {
    std::string bytes = read_text(file);
    SCOPED_TRACE(file.string());
    target(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    // Every prefix too: truncation is the commonest damage and must never crash or hang.
    for (size_t cut = 0; cut < bytes.size(); cut += 1 + bytes.size() / 64)
      target(reinterpret_cast<const uint8_t*>(bytes.data()), cut);
    ++count;
  }
  return count;
}

}  // namespace

TEST(FuzzCorpus, Proc) { EXPECT_GT(replay("proc", cohort::scene::fuzz::fuzz_proc, "assets/testmap/maps", ".proc"), 0); }
TEST(FuzzCorpus, Map) { EXPECT_GT(replay("map", cohort::scene::fuzz::fuzz_map, "assets/testmap/maps", ".map"), 0); }
TEST(FuzzCorpus, Mtr) { EXPECT_GT(replay("mtr", cohort::scene::fuzz::fuzz_mtr, "assets/testmap/materials", ".mtr"), 0); }
TEST(FuzzCorpus, Image) { EXPECT_GT(replay("image", cohort::scene::fuzz::fuzz_image), 0); }
TEST(FuzzCorpus, Ase) { EXPECT_GT(replay("ase", cohort::scene::fuzz::fuzz_ase, "assets/testmap/models/testmap", ".ase"), 0); }
TEST(FuzzCorpus, Lwo) { EXPECT_GT(replay("lwo", cohort::scene::fuzz::fuzz_lwo, "assets/testmap/models/testmap", ".lwo"), 0); }
TEST(FuzzCorpus, Md5Mesh) {
  EXPECT_GT(replay("md5", cohort::scene::fuzz::fuzz_md5, "assets/testmap/models/testmap", ".md5mesh"), 0);
}
TEST(FuzzCorpus, Def) { EXPECT_GT(replay("def", cohort::scene::fuzz::fuzz_def, "assets/testmap/def", ".def"), 0); }
TEST(FuzzCorpus, Skin) { EXPECT_GT(replay("def", cohort::scene::fuzz::fuzz_def, "assets/testmap/skins", ".skin"), 0); }
TEST(FuzzCorpus, Md5Anim) {
  EXPECT_GT(replay("md5", cohort::scene::fuzz::fuzz_md5, "assets/testmap/models/testmap", ".md5anim"), 0);
}
