#include "cohort/test_support/scene_churn.h"

#include <algorithm>
#include <cmath>

#include "cohort/commit/array_diff.h"

namespace cohort::test {

using commit::BlasUpload;
using commit::CommitBuffer;
using commit::TexelUpload;
using commit::TracerScene;

SceneChurn::SceneChurn(uint32_t seed) : rng_(seed) {
  for (int i = 0; i < 3; ++i) add_blas(master_, nullptr);
  master_.instances.resize(20);
  for (auto& inst : master_.instances) randomize(inst);
  master_.lights.resize(4);
  for (auto& l : master_.lights) randomize(l);
  master_.materials.resize(6);
  for (auto& m : master_.materials) randomize(m);
  master_.tlas_nodes.resize(39);
  for (auto& n : master_.tlas_nodes) randomize(n);
}

CommitBuffer SceneChurn::step(uint64_t frame, bool heavy) {
  TracerScene before_small;  // only the arrays that are diffed
  before_small.instances = master_.instances;
  before_small.lights = master_.lights;
  before_small.materials = master_.materials;
  before_small.tlas_nodes = master_.tlas_nodes;
  before_small.textures = master_.textures;
  CommitBuffer out;
  out.set_frame(frame);

  int moves = heavy ? int(master_.instances.size()) : pick(1, 5);
  for (int i = 0; i < moves && !master_.instances.empty(); ++i)
    randomize(master_.instances[pick(0, int(master_.instances.size()) - 1)]);
  if (pick(0, 9) == 0) master_.instances.resize(pick(5, 40), KInstance{});
  for (auto& inst : master_.instances)
    if (inst.mask == 0) randomize(inst);  // freshly grown slots get content
  std::shuffle(master_.tlas_nodes.begin(), master_.tlas_nodes.end(), rng_);
  master_.tlas_nodes.resize(master_.instances.size() * 2 - 1, KBvhNode{});
  if (pick(0, 2) == 0) randomize(master_.lights[pick(0, int(master_.lights.size()) - 1)]);
  if (pick(0, 19) == 0) {
    master_.lights.resize(pick(1, 8));
    for (auto& l : master_.lights) if (l.type == 0 && l.origin[0] == 0.0f) randomize(l);
  }
  if (pick(0, 9) == 0) {
    master_.materials.push_back({});
    randomize(master_.materials.back());
  }
  if (pick(0, 7) == 0) randomize(master_.materials[pick(0, int(master_.materials.size()) - 1)]);
  if (pick(0, 14) == 0) add_blas(master_, &out);
  if (pick(0, 14) == 0) add_texture(master_, &out);
  if (pick(0, 1) == 0) {
    master_.camera.origin[0] = uniform();
    out.set_camera(master_.camera);
  }

  commit::diff_instances(before_small.instances, master_.instances, out);
  commit::diff_tlas(before_small.tlas_nodes, master_.tlas_nodes, out);
  commit::diff_lights(before_small.lights, master_.lights, out);
  commit::diff_materials(before_small.materials, master_.materials, out);
  commit::diff_textures(before_small.textures, master_.textures, out);
  master_.version = frame;
  return out;
}

void SceneChurn::randomize(KInstance& inst) {
  fill_floats(inst);
  inst.blas = uint32_t(pick(0, int(master_.blases.size()) - 1));
  inst.mask = K_MASK_PRIMARY | K_MASK_SHADOW;
}

void SceneChurn::randomize(KLight& l) {
  fill_floats(l);
  l.type = K_LIGHT_POINT;
  l.origin[0] = 1.0f + std::abs(uniform());
}

void SceneChurn::randomize(KMaterial& m) {
  fill_floats(m);
  m.flags = uint32_t(pick(0, 255));
}

void SceneChurn::randomize(KBvhNode& n) { fill_floats(n); }

void SceneChurn::add_blas(TracerScene& s, CommitBuffer* out) {
  BlasUpload up;
  up.blas_index = uint32_t(s.blases.size());
  up.vertex_offset = uint32_t(s.vertices.size());
  up.triangle_offset = uint32_t(s.triangles.size());
  up.node_offset = uint32_t(s.blas_nodes.size());
  up.vertices.resize(pick(3, 30));
  for (auto& v : up.vertices) fill_floats(v);
  // Every other BLAS carries vertex colours, the rest leave them white (an empty array); derived from the
  // index so that the random sequence, and with it every other record, stays as it was.
  if (up.blas_index % 2 == 1)
    for (uint32_t v = 0; v < up.vertices.size(); ++v) up.vertex_colors.push_back(0x9E3779B9u * (up.blas_index * 64u + v + 1u));
  up.triangles.resize(pick(1, 10));
  for (auto& t : up.triangles) t = {up.vertex_offset, up.vertex_offset + 1, up.vertex_offset + 2, 0};
  up.nodes.resize(up.triangles.size() * 2 - 1);
  for (auto& n : up.nodes) randomize(n);
  up.blas = {up.node_offset, uint32_t(up.nodes.size()), up.triangle_offset, uint32_t(up.triangles.size())};
  s.vertices.insert(s.vertices.end(), up.vertices.begin(), up.vertices.end());
  if (up.vertex_colors.empty()) s.vertex_colors.insert(s.vertex_colors.end(), up.vertices.size(), K_VERTEX_COLOR_WHITE);
  else s.vertex_colors.insert(s.vertex_colors.end(), up.vertex_colors.begin(), up.vertex_colors.end());
  s.triangles.insert(s.triangles.end(), up.triangles.begin(), up.triangles.end());
  s.blas_nodes.insert(s.blas_nodes.end(), up.nodes.begin(), up.nodes.end());
  s.blases.push_back(up.blas);
  if (out) out->add_blas(std::move(up));
}

void SceneChurn::add_texture(TracerScene& s, CommitBuffer* out) {
  TexelUpload up;
  up.offset = uint32_t(s.texels.size());
  uint32_t w = uint32_t(pick(1, 8)), h = uint32_t(pick(1, 8));
  up.texels.resize(size_t(w) * h);
  for (auto& t : up.texels) t = uint32_t(rng_());
  KTexture tex{up.offset, w, h, K_TEX_SRGB | (1u << 8)};
  if (!s.textures.empty() && pick(0, 2) == 0)
    s.textures[pick(0, int(s.textures.size()) - 1)] = tex;
  else
    s.textures.push_back(tex);
  s.texels.insert(s.texels.end(), up.texels.begin(), up.texels.end());
  if (out) out->add_texels(std::move(up));
}

}  // namespace cohort::test
