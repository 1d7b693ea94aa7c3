#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  cohort::scene::fuzz::fuzz_def(data, size);
  return 0;
}
