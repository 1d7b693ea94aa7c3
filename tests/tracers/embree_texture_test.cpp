// The Embree tracer's SSE bilinear read (K_TEXEL_BILINEAR, cohort/tracers/embree_texture.h) against the
// portable scalar read it replaces, on random textures: sRGB and linear, wrapped and clamped, odd and
// power-of-two sizes, coordinates far outside [0, 1].
#ifdef COHORT_HAVE_EMBREE
#include "cohort/tracers/embree_texture.h"  // first: k_texture_sample_level below reads through the hook
#endif
#include "cohort/kernel/texture.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#ifdef K_TEXEL_BILINEAR
namespace {

// texture.h's bilinear read without the hook: four k_texel_fetch calls and the scalar blend.
KVec4 portable_bilinear(const KSceneView& scene, kuint tex, float s, float t) {
  const KTexture tx = scene.textures[tex];
  const kuint flags = k_tex_flags(tx), clamp = flags & K_TEX_CLAMP, w = tx.width, h = tx.height;
  const float x = s * (float)w - 0.5f, y = t * (float)h - 0.5f;
  const float fx0 = k_floor(x), fy0 = k_floor(y), ax = x - fx0, ay = y - fy0;
  const int x0 = (int)fx0, y0 = (int)fy0;
  const kuint xa = k_tex_coord(x0, w, clamp), xb = k_tex_coord(x0 + 1, w, clamp);
  const kuint ya = k_tex_coord(y0, h, clamp), yb = k_tex_coord(y0 + 1, h, clamp);
  const KVec4 c[4] = {k_texel_fetch(scene.texels, tx.offset, w, xa, ya, flags),
                      k_texel_fetch(scene.texels, tx.offset, w, xb, ya, flags),
                      k_texel_fetch(scene.texels, tx.offset, w, xa, yb, flags),
                      k_texel_fetch(scene.texels, tx.offset, w, xb, yb, flags)};
  const float wt[4] = {(1.0f - ax) * (1.0f - ay), ax * (1.0f - ay), (1.0f - ax) * ay, ax * ay};
  KVec4 r = v4(0.0f, 0.0f, 0.0f, 0.0f);
  for (int i = 0; i < 4; ++i)
    r = v4(r.x + c[i].x * wt[i], r.y + c[i].y * wt[i], r.z + c[i].z * wt[i], r.w + c[i].w * wt[i]);
  return r;
}

TEST(EmbreeTexture, SseBilinearReadMatchesThePortableRead) {
  std::mt19937 rng(18);
  std::vector<KTexture> textures;
  std::vector<kuint> texels;
  const kuint sizes[][2] = {{8, 4}, {5, 3}, {1, 1}, {64, 16}, {7, 32}};
  for (const auto& size : sizes)
    for (kuint flags : {0u, K_TEX_SRGB, K_TEX_CLAMP, K_TEX_CLAMP | K_TEX_SRGB}) {
      textures.push_back({static_cast<kuint>(texels.size()), size[0], size[1], flags | (1u << 8)});
      for (kuint i = 0; i < size[0] * size[1]; ++i) texels.push_back(static_cast<kuint>(rng()));
    }
  KSceneView scene{};
  scene.textures = textures.data();
  scene.texels = texels.data();

  std::uniform_real_distribution<float> coord(-3.0f, 4.0f);
  int compared = 0;
  for (kuint tex = 0; tex < textures.size(); ++tex)
    for (int k = 0; k < 2000; ++k) {
      const float s = coord(rng), t = coord(rng);
      const KVec4 sse = k_texture_sample_level(&scene, tex, s, t, 0u);
      const KVec4 ref = portable_bilinear(scene, tex, s, t);
      // The same operations per channel; only the compiler's fused multiply-adds may round differently.
      ASSERT_NEAR(sse.x, ref.x, 1e-6f) << "texture " << tex << " at (" << s << ", " << t << ")";
      ASSERT_NEAR(sse.y, ref.y, 1e-6f) << "texture " << tex << " at (" << s << ", " << t << ")";
      ASSERT_NEAR(sse.z, ref.z, 1e-6f) << "texture " << tex << " at (" << s << ", " << t << ")";
      ASSERT_NEAR(sse.w, ref.w, 1e-6f) << "texture " << tex << " at (" << s << ", " << t << ")";
      ++compared;
    }
  EXPECT_EQ(compared, 20 * 2000);
}

}  // namespace
#endif
