#include <cstdint>

#include "cohort/scene/image_decode.h"

namespace cohort::scene {

namespace {

struct Cursor {
  std::string_view bytes;
  size_t pos = 0;
  bool take(size_t n, const uint8_t*& out) {
    if (bytes.size() - pos < n) return false;
    out = reinterpret_cast<const uint8_t*>(bytes.data() + pos);
    pos += n;
    return true;
  }
};

void to_rgba(const uint8_t* p, int bytes_per_pixel, uint8_t* out) {
  switch (bytes_per_pixel) {
    case 1: out[0] = out[1] = out[2] = p[0]; out[3] = 255; break;
    case 2: {  // A1R5G5B5, little endian
      unsigned v = p[0] | (p[1] << 8);
      out[0] = static_cast<uint8_t>(((v >> 10) & 31) * 255 / 31);
      out[1] = static_cast<uint8_t>(((v >> 5) & 31) * 255 / 31);
      out[2] = static_cast<uint8_t>((v & 31) * 255 / 31);
      out[3] = 255;
      break;
    }
    case 3: out[0] = p[2]; out[1] = p[1]; out[2] = p[0]; out[3] = 255; break;
    default: out[0] = p[2]; out[1] = p[1]; out[2] = p[0]; out[3] = p[3]; break;
  }
}

}  // namespace

std::optional<Image> decode_tga(std::string_view bytes, std::string& error) {
  if (bytes.size() < 18) {
    error = "TGA header truncated";
    return std::nullopt;
  }
  const auto* h = reinterpret_cast<const uint8_t*>(bytes.data());
  int id_length = h[0], colormap_type = h[1], type = h[2];
  int width = h[12] | (h[13] << 8), height = h[14] | (h[15] << 8), bits = h[16], descriptor = h[17];
  bool rle = type == 10 || type == 11;
  bool grey = type == 3 || type == 11;
  if (colormap_type != 0 || !(type == 2 || type == 3 || type == 10 || type == 11)) {
    error = "unsupported TGA type " + std::to_string(type) + " (only true-colour and grey are read)";
    return std::nullopt;
  }
  if (grey ? bits != 8 : !(bits == 16 || bits == 24 || bits == 32)) {
    error = "unsupported TGA pixel size " + std::to_string(bits);
    return std::nullopt;
  }
  if (width <= 0 || height <= 0 || static_cast<long long>(width) * height > kMaxImagePixels) {
    error = "bad TGA size " + std::to_string(width) + "x" + std::to_string(height);
    return std::nullopt;
  }
  const int bpp = bits / 8;
  Cursor in{bytes, 18 + static_cast<size_t>(id_length)};
  if (in.pos > bytes.size()) {
    error = "TGA header truncated";
    return std::nullopt;
  }
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (!rle && bytes.size() - in.pos < pixels * bpp) {
    error = "TGA pixel data truncated";
    return std::nullopt;
  }
  Image image;
  image.width = width;
  image.height = height;
  image.rgba.resize(pixels * 4);
  size_t done = 0;
  const uint8_t* p = nullptr;
  while (done < pixels) {
    if (!rle) {
      in.take(static_cast<size_t>(bpp), p);
      to_rgba(p, bpp, &image.rgba[done++ * 4]);
      continue;
    }
    const uint8_t* packet = nullptr;
    if (!in.take(1, packet)) break;
    size_t run = (packet[0] & 0x7f) + 1u;
    if (run > pixels - done) run = pixels - done;
    if (packet[0] & 0x80) {
      if (!in.take(static_cast<size_t>(bpp), p)) break;
      for (size_t i = 0; i < run; ++i) to_rgba(p, bpp, &image.rgba[done++ * 4]);
    } else {
      for (size_t i = 0; i < run; ++i) {
        if (!in.take(static_cast<size_t>(bpp), p)) break;
        to_rgba(p, bpp, &image.rgba[done++ * 4]);
      }
    }
    if (in.pos >= bytes.size() && done < pixels) break;
  }
  if (done < pixels) {
    error = "TGA run-length data truncated";
    return std::nullopt;
  }
  const bool top_first = (descriptor & 0x20) != 0, right_first = (descriptor & 0x10) != 0;
  const size_t row_bytes = static_cast<size_t>(width) * 4;
  if (!top_first)
    for (int y = 0; y < height / 2; ++y)
      std::swap_ranges(image.rgba.begin() + y * row_bytes, image.rgba.begin() + (y + 1) * row_bytes,
                       image.rgba.begin() + (height - 1 - y) * row_bytes);
  if (right_first)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width / 2; ++x)
        std::swap_ranges(image.rgba.begin() + y * row_bytes + x * 4, image.rgba.begin() + y * row_bytes + x * 4 + 4,
                         image.rgba.begin() + y * row_bytes + (width - 1 - x) * 4);
  return image;
}

}  // namespace cohort::scene
