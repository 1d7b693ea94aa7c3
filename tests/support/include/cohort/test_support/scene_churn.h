// A master TracerScene that changes every frame the way the core changes it (instances move and come
// and go, the TLAS is replaced, lights flicker and are added/removed, materials change, new BLASes
// and textures arrive, the camera moves) and produces each frame's commit records: the commit tests'
// workload.
#pragma once

#include <cstring>
#include <random>

#include "cohort/commit/commit_buffer.h"

namespace cohort::test {

class SceneChurn {
 public:
  explicit SceneChurn(uint32_t seed);

  const commit::TracerScene& master() const { return master_; }

  // Change the master for `frame` and return the records that carry the change.
  commit::CommitBuffer step(uint64_t frame, bool heavy = false);

 private:
  int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  float uniform() { return std::uniform_real_distribution<float>(-100.0f, 100.0f)(rng_); }
  template <class T> void fill_floats(T& value) {
    static_assert(sizeof(T) % 4 == 0);
    float f[sizeof(T) / 4];
    for (float& x : f) x = uniform();
    std::memcpy(&value, f, sizeof(T));
  }
  void randomize(KInstance& inst);
  void randomize(KLight& l);
  void randomize(KMaterial& m);
  void randomize(KBvhNode& n);
  void add_blas(commit::TracerScene& s, commit::CommitBuffer* out);
  // A texture appended to the table, its texels appended to the buffer; sometimes an existing slot
  // is pointed at the new texels instead (a redefined texture).
  void add_texture(commit::TracerScene& s, commit::CommitBuffer* out);

  std::mt19937 rng_;
  commit::TracerScene master_;
};

}  // namespace cohort::test
