// The integrator's building blocks, compiled as plain C++: random numbers, texture reads, BRDF
// sampling against its own evaluation.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "cohort/kernel/brdf.h"
#include "cohort/kernel/rng.h"

TEST(KernelRng, SameSeedSameSequenceAndUniform) {
  KRng a = k_rng_seed(3, 4, 5, 6), b = k_rng_seed(3, 4, 5, 6), c = k_rng_seed(4, 3, 5, 6);
  double sum = 0.0;
  int same_as_other_pixel = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    float x = k_rng_next(&a);
    EXPECT_EQ(x, k_rng_next(&b));
    same_as_other_pixel += x == k_rng_next(&c);
    ASSERT_GE(x, 0.0f);
    ASSERT_LT(x, 1.0f);
    sum += x;
  }
  EXPECT_NEAR(sum / n, 0.5, 0.01);
  EXPECT_LT(same_as_other_pixel, 5);
}

namespace {

struct TextureFixture {
  std::vector<KTexture> textures;
  std::vector<kuint> texels;
  KSceneView view{};
  // 2x2: (0,0) R=0, (1,0) R=200, (0,1) R=100, (1,1) R=255; alpha 255.
  explicit TextureFixture(kuint flags) {
    texels = {0xFF000000u, 0xFF0000C8u, 0xFF000064u, 0xFF0000FFu};
    textures.push_back(KTexture{0, 2, 2, flags | (1u << 8)});
    view.textures = textures.data();
    view.texels = texels.data();
  }
  float red(float s, float t) { return k_texture_sample(&view, 0, s, t).x; }
};

}  // namespace

TEST(KernelTexture, BilinearWrapAndClamp) {
  TextureFixture wrap(0u);
  EXPECT_NEAR(wrap.red(0.25f, 0.25f), 0.0f, 1e-6f) << "texel centre";
  EXPECT_NEAR(wrap.red(0.75f, 0.25f), 200.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(wrap.red(0.5f, 0.25f), 100.0f / 255.0f, 1e-6f) << "halfway between texels";
  EXPECT_NEAR(wrap.red(0.0f, 0.25f), 100.0f / 255.0f, 1e-6f) << "wraps to the last column";
  EXPECT_NEAR(wrap.red(1.25f, 0.25f), 0.0f, 1e-6f);
  EXPECT_NEAR(wrap.red(0.25f, 0.75f), 100.0f / 255.0f, 1e-6f) << "t = 0.75 is the second stored row";
  TextureFixture clamp(K_TEX_CLAMP);
  EXPECT_NEAR(clamp.red(0.0f, 0.25f), 0.0f, 1e-6f) << "clamps to the first column";
  EXPECT_NEAR(clamp.red(-3.0f, 0.25f), 0.0f, 1e-6f);
  TextureFixture srgb(K_TEX_SRGB);
  EXPECT_NEAR(srgb.red(0.75f, 0.75f), 1.0f, 1e-5f);
  EXPECT_NEAR(srgb.red(0.25f, 0.75f), 0.127f, 0.003f) << "sRGB 100/255 decodes to about 0.127";
}

namespace {

KSurface test_surface(float albedo, float spec, float roughness) {
  KSurface s{};
  s.normal = v3(0, 0, 1);
  s.geo_normal = s.normal;
  s.albedo = v3s(albedo);
  s.specular = v3s(spec);
  s.roughness = roughness;
  s.metallic = 0.0f;
  return s;
}

}  // namespace

// A diffuse surface's sampled weight is exactly its albedo.
TEST(KernelBrdf, DiffuseSamplingWeightIsAlbedo) {
  KSurface s = test_surface(0.6f, 0.0f, 0.5f);
  KRng rng = k_rng_seed(1, 2, 3, 4);
  for (int i = 0; i < 1000; ++i) {
    KVec3 wi;
    KVec3 w = k_brdf_sample(&s, v3_normalize(v3(0.3f, 0.1f, 1.0f)), k_rng_next(&rng), k_rng_next(&rng),
                            k_rng_next(&rng), &wi);
    if (w.x == 0.0f) continue;
    ASSERT_NEAR(w.x, 0.6f, 1e-4f);
  }
}

// Importance-sampled estimate of the reflectance integral agrees with a uniform-hemisphere estimate
// of the same k_brdf_eval_cos: the sampler's pdf matches the directions it draws.
TEST(KernelBrdf, SamplerPdfMatchesItsDirections) {
  for (float roughness : {0.2f, 0.5f, 0.9f}) {
    KSurface s = test_surface(0.3f, 0.5f, roughness);
    KVec3 wo = v3_normalize(v3(0.5f, 0.0f, 1.0f));
    KRng rng = k_rng_seed(7, 8, 9, 10);
    const int n = 400000;
    double importance = 0.0, uniform = 0.0;
    for (int i = 0; i < n; ++i) {
      KVec3 wi;
      importance += k_brdf_sample(&s, wo, k_rng_next(&rng), k_rng_next(&rng), k_rng_next(&rng), &wi).x;
      float z = k_rng_next(&rng), phi = 2.0f * K_PI * k_rng_next(&rng);
      float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      KVec3 u = v3(r * std::cos(phi), r * std::sin(phi), z);
      uniform += k_brdf_eval_cos(&s, wo, u, 1.0f).x * 2.0f * K_PI;
    }
    EXPECT_NEAR(importance / n, uniform / n, 0.02 * uniform / n) << "roughness " << roughness;
  }
}
