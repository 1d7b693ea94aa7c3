/* Texture reads from the shared RGBA8 texel buffer: bilinear, wrap or clamp, sRGB decode, mip
 * levels stored one after another after level 0. */
#ifndef COHORT_KERNEL_TEXTURE_H
#define COHORT_KERNEL_TEXTURE_H
#include "scene_view.h"
#include "sampling.h"

typedef struct KVec4 { float x, y, z, w; } KVec4;

KFN KVec4 v4(float x, float y, float z, float w) { KVec4 r; r.x = x; r.y = y; r.z = z; r.w = w; return r; }
KFN KVec3 v4_rgb(KVec4 c) { return v3(c.x, c.y, c.z); }

/* sRGB decode by a cubic fit (error below 0.3% of full scale, exact at 0 and 1): four texels per
 * bilinear read made the exact pow() the integrator's largest cost on the CPU. */
KFN float k_srgb_to_linear(float c) {
  return c * (c * (c * 0.305306011f + 0.682171111f) + 0.012522878f);
}

KFN kuint k_tex_flags(KTexture t) { return t.flags_and_levels & 0xFFu; }
KFN kuint k_tex_levels(KTexture t) {
  kuint n = (t.flags_and_levels >> 8) & 0xFFu;
  return n == 0u ? 1u : n;
}

/* A tracer may route texel reads through its own cache path (CUDA: a texture object), or replace the
 * bilinear blend of four texels (K_TEXEL_BILINEAR, k_texture_sample_level). */
#ifndef K_TEXEL_LOAD
#define K_TEXEL_LOAD(texels, index) ((texels)[index])
#endif

KFN KVec4 k_texel_fetch(KGLOBAL const kuint* texels, kuint offset, kuint width, kuint x, kuint y, kuint flags) {
  kuint p = K_TEXEL_LOAD(texels, offset + y * width + x);
  KVec4 c = v4((float)(p & 0xFFu), (float)((p >> 8) & 0xFFu), (float)((p >> 16) & 0xFFu), (float)(p >> 24));
  c = v4(c.x * (1.0f / 255.0f), c.y * (1.0f / 255.0f), c.z * (1.0f / 255.0f), c.w * (1.0f / 255.0f));
  if (flags & K_TEX_SRGB) {
    c.x = k_srgb_to_linear(c.x);
    c.y = k_srgb_to_linear(c.y);
    c.z = k_srgb_to_linear(c.z);
  }
  return c;
}

/* Wrapping is a mask on power-of-two sizes (nearly every Doom 3 image): an integer division costs tens
 * of cycles on CPUs and GPUs alike, and two are needed per bilinear read. */
KFN kuint k_tex_coord(int i, kuint size, kuint clamp) {
  int n = (int)size;
  if (clamp) return (kuint)(i < 0 ? 0 : (i >= n ? n - 1 : i));
  if ((size & (size - 1u)) == 0u) return (kuint)i & (size - 1u);
  int m = i % n;
  return (kuint)(m < 0 ? m + n : m);
}

/* Bilinear sample at (s, t) of mip level `level` (clamped to the levels present). t = 0 is the first
 * stored row (the top of the image), as in Doom 3. */
KFN KVec4 k_texture_sample_level(const KSceneView* scene, kuint tex, float s, float t, kuint level) {
  KTexture tx = scene->textures[tex];
  kuint flags = k_tex_flags(tx);
  kuint levels = k_tex_levels(tx);
  if (level >= levels) level = levels - 1u;
  kuint offset = tx.offset, w = tx.width, h = tx.height;
  for (kuint l = 0u; l < level; ++l) {
    offset += w * h;
    w = w > 1u ? w >> 1 : 1u;
    h = h > 1u ? h >> 1 : 1u;
  }
  kuint clamp = flags & K_TEX_CLAMP;
  float x = s * (float)w - 0.5f, y = t * (float)h - 0.5f;
  float fx0 = k_floor(x), fy0 = k_floor(y);
  float ax = x - fx0, ay = y - fy0;
  int x0 = (int)fx0, y0 = (int)fy0;
  kuint xa = k_tex_coord(x0, w, clamp), ya = k_tex_coord(y0, h, clamp);
  /* The next texel without a second integer division (wrapping: the one after the last is the first). */
  kuint xb = clamp ? k_tex_coord(x0 + 1, w, clamp) : (xa + 1u == w ? 0u : xa + 1u);
  kuint yb = clamp ? k_tex_coord(y0 + 1, h, clamp) : (ya + 1u == h ? 0u : ya + 1u);
#ifdef K_TEXEL_BILINEAR
  /* A tracer's own bilinear read of the four texels, with the same result (the Embree tracer: one SSE
   * vector per texel instead of sixteen scalar conversions and twelve sRGB polynomials). */
  {
    float c[4];
    kuint row_a = offset + ya * w, row_b = offset + yb * w;
    K_TEXEL_BILINEAR(scene->texels, row_a + xa, row_a + xb, row_b + xa, row_b + xb, ax, ay, flags & K_TEX_SRGB, c);
    return v4(c[0], c[1], c[2], c[3]);
  }
#endif
  KVec4 c00 = k_texel_fetch(scene->texels, offset, w, xa, ya, flags);
  KVec4 c10 = k_texel_fetch(scene->texels, offset, w, xb, ya, flags);
  KVec4 c01 = k_texel_fetch(scene->texels, offset, w, xa, yb, flags);
  KVec4 c11 = k_texel_fetch(scene->texels, offset, w, xb, yb, flags);
  float w00 = (1.0f - ax) * (1.0f - ay), w10 = ax * (1.0f - ay), w01 = (1.0f - ax) * ay, w11 = ax * ay;
  return v4(c00.x * w00 + c10.x * w10 + c01.x * w01 + c11.x * w11,
            c00.y * w00 + c10.y * w10 + c01.y * w01 + c11.y * w11,
            c00.z * w00 + c10.z * w10 + c01.z * w01 + c11.z * w11,
            c00.w * w00 + c10.w * w10 + c01.w * w01 + c11.w * w11);
}

KFN KVec4 k_texture_sample(const KSceneView* scene, kuint tex, float s, float t) {
  return k_texture_sample_level(scene, tex, s, t, 0u);
}

/* Mip level for a footprint of `texels` level-0 texels across (nearest level, so one bilinear read):
 * floor(log2(texels) + 0.5) = floor(log2(texels * sqrt 2)), the binary exponent of texels * sqrt 2, read
 * from its bits instead of a log2 call. */
KFN kuint k_mip_level(float texels) {
  if (!(texels > 1.0f)) return 0u;
  float scaled = k_fmin(texels * 1.41421356f, 3.0e38f); /* finite: infinity would read as level 128 */
  return ((k_as_uint(scaled) >> 23) & 0xFFu) - 127u;
}

/* Bilinear read at the level matching a footprint given in texture-space units (1 = the whole
 * texture): footprint * sqrt(width * height) level-0 texels. */
KFN KVec4 k_texture_sample_footprint(const KSceneView* scene, kuint tex, float s, float t, float footprint) {
  KTexture tx = scene->textures[tex];
  float texels = footprint * k_sqrt((float)tx.width * (float)tx.height);
  return k_texture_sample_level(scene, tex, s, t, k_mip_level(texels));
}

/* Tangent-space normal from a normal map (X in R, Y in G, Z in B), not normalised. */
KFN KVec3 k_texture_normal(const KSceneView* scene, kuint tex, float s, float t, float footprint) {
  KVec4 c = k_texture_sample_footprint(scene, tex, s, t, footprint);
  return v3(c.x * 2.0f - 1.0f, c.y * 2.0f - 1.0f, c.z * 2.0f - 1.0f);
}

#endif
