#include "cohort/scene/image_ops.h"

#include <algorithm>
#include <cmath>

namespace cohort::scene {

namespace {

uint8_t to_byte(float v) { return static_cast<uint8_t>(std::clamp(v, 0.0f, 255.0f) + 0.5f); }

glm::vec3 decode_normal(const uint8_t* p) {
  return glm::vec3(p[0], p[1], p[2]) / 127.5f - glm::vec3(1.0f);
}

void encode_normal(glm::vec3 n, uint8_t* p) {
  float len = glm::length(n);
  n = len > 1e-12f ? n / len : glm::vec3(0, 0, 1);
  p[0] = to_byte((n.x + 1.0f) * 127.5f);
  p[1] = to_byte((n.y + 1.0f) * 127.5f);
  p[2] = to_byte((n.z + 1.0f) * 127.5f);
  p[3] = 255;
}

const uint8_t* texel_resampled(const Image& image, int x, int y, int width, int height) {
  int sx = static_cast<int>(static_cast<long long>(x) * image.width / width);
  int sy = static_cast<int>(static_cast<long long>(y) * image.height / height);
  return &image.rgba[(static_cast<size_t>(sy) * image.width + sx) * 4];
}

Image same_size_as(const Image& a) {
  Image out;
  out.name = a.name;
  out.width = a.width;
  out.height = a.height;
  out.rgba.resize(a.rgba.size());
  return out;
}

}  // namespace

Image heightmap_to_normals(const Image& height, float scale) {
  Image out = same_size_as(height);
  out.is_normal_map = true;
  const int w = height.width, h = height.height;
  auto level = [&](int x, int y) {
    x = (x % w + w) % w;
    y = (y % h + h) % h;
    const uint8_t* p = &height.rgba[(static_cast<size_t>(y) * w + x) * 4];
    return (p[0] + p[1] + p[2]) / (3.0f * 255.0f);
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float dx = (level(x + 1, y) - level(x - 1, y)) * 0.5f * scale;
      float dy = (level(x, y + 1) - level(x, y - 1)) * 0.5f * scale;
      // Rows run top to bottom while +t (green) points up the texture, hence +dy.
      encode_normal(glm::vec3(-dx, dy, 1.0f), &out.rgba[(static_cast<size_t>(y) * w + x) * 4]);
    }
  }
  return out;
}

Image add_normals(const Image& a, const Image& b) {
  Image out = same_size_as(a);
  out.is_normal_map = true;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      size_t i = (static_cast<size_t>(y) * a.width + x) * 4;
      glm::vec3 na = decode_normal(&a.rgba[i]), nb = decode_normal(texel_resampled(b, x, y, a.width, a.height));
      encode_normal(glm::vec3(na.x + nb.x, na.y + nb.y, na.z * nb.z), &out.rgba[i]);
    }
  return out;
}

Image smooth_normals(const Image& normals) {
  Image out = same_size_as(normals);
  out.is_normal_map = true;
  const int w = normals.width, h = normals.height;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 sum(0.0f);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int sx = (x + dx + w) % w, sy = (y + dy + h) % h;
          sum += decode_normal(&normals.rgba[(static_cast<size_t>(sy) * w + sx) * 4]);
        }
      encode_normal(sum, &out.rgba[(static_cast<size_t>(y) * w + x) * 4]);
    }
  return out;
}

Image add_images(const Image& a, const Image& b) {
  Image out = same_size_as(a);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      size_t i = (static_cast<size_t>(y) * a.width + x) * 4;
      const uint8_t* pb = texel_resampled(b, x, y, a.width, a.height);
      for (int c = 0; c < 4; ++c) out.rgba[i + c] = static_cast<uint8_t>(std::min(255, a.rgba[i + c] + pb[c]));
    }
  return out;
}

Image scale_channels(const Image& image, const float factors[4]) {
  Image out = image;
  for (size_t i = 0; i < out.rgba.size(); ++i) out.rgba[i] = to_byte(out.rgba[i] * factors[i % 4]);
  return out;
}

Image invert_alpha(const Image& image) {
  Image out = image;
  for (size_t i = 3; i < out.rgba.size(); i += 4) out.rgba[i] = static_cast<uint8_t>(255 - out.rgba[i]);
  return out;
}

Image invert_color(const Image& image) {
  Image out = image;
  for (size_t i = 0; i < out.rgba.size(); ++i)
    if (i % 4 != 3) out.rgba[i] = static_cast<uint8_t>(255 - out.rgba[i]);
  return out;
}

Image make_intensity(const Image& image) {
  Image out = image;
  for (size_t i = 0; i < out.rgba.size(); i += 4) out.rgba[i + 1] = out.rgba[i + 2] = out.rgba[i + 3] = out.rgba[i];
  return out;
}

Image make_alpha(const Image& image) {
  Image out = image;
  for (size_t i = 0; i < out.rgba.size(); i += 4) {
    out.rgba[i + 3] = static_cast<uint8_t>((out.rgba[i] + out.rgba[i + 1] + out.rgba[i + 2]) / 3);
    out.rgba[i] = out.rgba[i + 1] = out.rgba[i + 2] = 255;
  }
  return out;
}

}  // namespace cohort::scene
