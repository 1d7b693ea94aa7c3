// Replays the fuzzers' seed corpus (and any crash inputs saved beside it) through every parser in
// the ordinary build, so that inputs which once crashed keep being checked without clang.
#include <gtest/gtest.h>

#include <filesystem>

#include "../../scene/fuzz/fuzz_targets.h"
#include "test_files.h"

namespace fs = std::filesystem;
using cohort::scene::test::read_text;

namespace {

int replay(const std::string& corpus, void (*target)(const uint8_t*, size_t)) {
  fs::path dir = fs::path(COHORT_SOURCE_DIR) / "scene/fuzz/corpus" / corpus;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::string bytes = read_text(entry.path());
    SCOPED_TRACE(entry.path().string());
    target(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    // Every prefix too: truncation is the commonest damage and must never crash or hang.
    for (size_t cut = 0; cut < bytes.size(); cut += 1 + bytes.size() / 64)
      target(reinterpret_cast<const uint8_t*>(bytes.data()), cut);
    ++count;
  }
  return count;
}

}  // namespace

TEST(FuzzCorpus, Proc) { EXPECT_GT(replay("proc", cohort::scene::fuzz::fuzz_proc), 0); }
TEST(FuzzCorpus, Map) { EXPECT_GT(replay("map", cohort::scene::fuzz::fuzz_map), 0); }
TEST(FuzzCorpus, Mtr) { EXPECT_GT(replay("mtr", cohort::scene::fuzz::fuzz_mtr), 0); }
TEST(FuzzCorpus, Image) { EXPECT_GT(replay("image", cohort::scene::fuzz::fuzz_image), 0); }
