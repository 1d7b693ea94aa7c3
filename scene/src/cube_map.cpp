#include "cohort/scene/cube_map.h"

#include <algorithm>
#include <cmath>

namespace cohort::scene {

namespace {

Image transposed(const Image& in) {
  Image out = in;
  const int n = in.width;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      std::copy_n(&in.rgba[(size_t(x) * n + y) * 4], 4, &out.rgba[(size_t(y) * n + x) * 4]);
  return out;
}

Image flipped(const Image& in, bool horizontal, bool vertical) {
  Image out = in;
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      int sx = horizontal ? in.width - 1 - x : x, sy = vertical ? in.height - 1 - y : y;
      std::copy_n(&in.rgba[(size_t(sy) * in.width + sx) * 4], 4, &out.rgba[(size_t(y) * in.width + x) * 4]);
    }
  return out;
}

}  // namespace

const char* cube_face_suffix(CubeMapKind kind, int face) {
  static const char* const axis[6] = {"_px", "_nx", "_py", "_ny", "_pz", "_nz"};
  static const char* const camera[6] = {"_forward", "_back", "_left", "_right", "_up", "_down"};
  if (face < 0 || face > 5) return "";
  return kind == CubeMapKind::Camera ? camera[face] : axis[face];
}

Image camera_image_to_cube_face(const Image& image, int face) {
  switch (face) {
    case 0: return transposed(image);                            // forward
    case 1: return flipped(transposed(image), true, true);       // back
    case 2: return flipped(image, false, true);                  // left
    case 3: return flipped(image, true, false);                  // right
    case 4: case 5: return transposed(image);                    // up, down
    default: return image;
  }
}

glm::mat3 wobble_sky_axes(float degrees, float speed, float rotate, float seconds) {
  const float pi = 3.14159265358979f;
  const float w = degrees * pi / 180.0f, a = speed * 2.0f * pi / 60.0f * seconds, b = rotate * 2.0f * pi / 60.0f * seconds;
  const float s = std::sin(a), c = std::cos(a), ws = std::sin(w), wc = std::cos(w);
  glm::vec3 z(ws * c, ws * s, wc);
  glm::vec3 y(-s * s * ws, 0.0f, -s * ws * ws);
  y.y = std::sqrt(std::fabs(1.0f - (y.x * y.x + y.z * y.z)));
  y = glm::normalize(y - glm::dot(z, y) * z);
  glm::vec3 x = glm::cross(y, z);
  const float rs = std::sin(b), rc = std::cos(b);
  return glm::mat3(x * rc + y * rs, y * rc - x * rs, z);
}

}  // namespace cohort::scene
