// Texture table and texel buffer: every image once in the texel buffer with its mip chain, and one
// KTexture per (image, use) pointing at those shared texels.
#include "gpu_scene_textures.h"

#include <algorithm>

namespace cohort::core {

uint32_t texture_slot(int image, TextureUse use, const scene::Scene& scene) {
  if (image < 0 || static_cast<size_t>(image) >= scene.images.size()) return K_NONE;
  const scene::Image& img = scene.images[static_cast<size_t>(image)];
  if (img.width <= 0 || img.height <= 0 || img.rgba.size() < static_cast<size_t>(img.width) * img.height * 4)
    return K_NONE;
  return static_cast<uint32_t>(use) * static_cast<uint32_t>(scene.images.size()) + static_cast<uint32_t>(image);
}

namespace {

uint32_t pack(const uint8_t* p) {
  return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}

// Appends level 0 and a 2x2 box-filtered chain down to 1x1; returns the level count.
uint32_t append_mip_chain(const scene::Image& img, std::vector<uint32_t>& texels) {
  int w = img.width, h = img.height;
  std::vector<uint8_t> level(img.rgba.begin(), img.rgba.begin() + static_cast<ptrdiff_t>(size_t(w) * h * 4));
  uint32_t levels = 0;
  for (;;) {
    for (size_t i = 0; i < size_t(w) * h; ++i) texels.push_back(pack(&level[i * 4]));
    ++levels;
    if ((w == 1 && h == 1) || levels == 255) break;
    int nw = std::max(1, w / 2), nh = std::max(1, h / 2);
    std::vector<uint8_t> next(size_t(nw) * nh * 4);
    for (int y = 0; y < nh; ++y)
      for (int x = 0; x < nw; ++x)
        for (int c = 0; c < 4; ++c) {
          int x0 = std::min(2 * x, w - 1), x1 = std::min(2 * x + 1, w - 1);
          int y0 = std::min(2 * y, h - 1), y1 = std::min(2 * y + 1, h - 1);
          int sum = level[(size_t(y0) * w + x0) * 4 + c] + level[(size_t(y0) * w + x1) * 4 + c] +
                    level[(size_t(y1) * w + x0) * 4 + c] + level[(size_t(y1) * w + x1) * 4 + c];
          next[(size_t(y) * nw + x) * 4 + c] = static_cast<uint8_t>((sum + 2) / 4);
        }
    level.swap(next);
    w = nw;
    h = nh;
  }
  return levels;
}

uint32_t use_flags(TextureUse use, bool normal_map) {
  if (normal_map) return K_TEX_NORMAL | (use == TextureUse::Surface ? 0u : K_TEX_CLAMP);
  switch (use) {
    case TextureUse::Surface: return K_TEX_SRGB;
    case TextureUse::LightImage: return K_TEX_SRGB | K_TEX_CLAMP;
    case TextureUse::Falloff: return K_TEX_CLAMP;
  }
  return 0u;
}

}  // namespace

void compile_textures(const scene::Scene& scene, commit::TracerScene& out) {
  size_t n = scene.images.size();
  out.textures.assign(n * kTextureUseCount, KTexture{0, 0, 0, 0});
  out.texels.clear();
  for (size_t i = 0; i < n; ++i) {
    const scene::Image& img = scene.images[i];
    if (texture_slot(static_cast<int>(i), TextureUse::Surface, scene) == K_NONE) continue;
    uint32_t offset = static_cast<uint32_t>(out.texels.size());
    uint32_t levels = append_mip_chain(img, out.texels);
    for (uint32_t use = 0; use < kTextureUseCount; ++use) {
      KTexture& t = out.textures[use * n + i];
      t.offset = offset;
      t.width = static_cast<uint32_t>(img.width);
      t.height = static_cast<uint32_t>(img.height);
      t.flags_and_levels = use_flags(static_cast<TextureUse>(use), img.is_normal_map) | (levels << 8);
    }
  }
}

}  // namespace cohort::core
