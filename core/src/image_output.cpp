#include "cohort/core/image_output.h"

#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#if defined(COHORT_HAVE_OIIO)
#include <OpenImageIO/imageio.h>
#endif

namespace cohort::core {
namespace {

std::string extension_of(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

void write_ppm(const std::filesystem::path& file, int width, int height, const std::vector<uint8_t>& rgba) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(fmt::format("{}: cannot open for writing", file.string()));
  out << "P6\n" << width << " " << height << "\n255\n";
  std::vector<uint8_t> rgb(size_t(width) * height * 3);
  for (size_t i = 0, n = size_t(width) * height; i < n; ++i) std::memcpy(&rgb[i * 3], &rgba[i * 4], 3);
  out.write(reinterpret_cast<const char*>(rgb.data()), std::streamsize(rgb.size()));
  if (!out) throw std::runtime_error(fmt::format("{}: write failed", file.string()));
}

// PFM stores rows bottom to top; a negative scale means little-endian.
void write_pfm(const std::filesystem::path& file, const FrameBuffer& frame) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(fmt::format("{}: cannot open for writing", file.string()));
  out << "PF\n" << frame.width << " " << frame.height << "\n-1.0\n";
  std::vector<float> row(size_t(frame.width) * 3);
  for (int y = frame.height - 1; y >= 0; --y) {
    const float* src = frame.row(y);
    for (int x = 0; x < frame.width; ++x) std::memcpy(&row[size_t(x) * 3], src + size_t(x) * 4, 3 * sizeof(float));
    out.write(reinterpret_cast<const char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
  }
  if (!out) throw std::runtime_error(fmt::format("{}: write failed", file.string()));
}

#if defined(COHORT_HAVE_OIIO)
void write_with_oiio(const std::filesystem::path& file, int width, int height, int channels, OIIO::TypeDesc type,
                     const void* pixels) {
  auto output = OIIO::ImageOutput::create(file.string());
  if (!output) throw std::runtime_error(fmt::format("{}: no image writer for this extension", file.string()));
  OIIO::ImageSpec spec(width, height, channels, type);
  if (!output->open(file.string(), spec) || !output->write_image(type, pixels) || !output->close())
    throw std::runtime_error(fmt::format("{}: {}", file.string(), output->geterror()));
}
#endif

}  // namespace

bool have_image_library() {
#if defined(COHORT_HAVE_OIIO)
  return true;
#else
  return false;
#endif
}

void write_ldr_image(const std::filesystem::path& file, int width, int height, const std::vector<uint8_t>& rgba) {
  if (rgba.size() != size_t(width) * height * 4)
    throw std::invalid_argument(fmt::format("{}: pixel buffer does not match {}x{}", file.string(), width, height));
  const std::string ext = extension_of(file);
  if (ext == ".ppm") return write_ppm(file, width, height, rgba);
#if defined(COHORT_HAVE_OIIO)
  write_with_oiio(file, width, height, 4, OIIO::TypeDesc::UINT8, rgba.data());
#else
  throw std::runtime_error(fmt::format("{}: this build has no OpenImageIO; write .ppm instead", file.string()));
#endif
}

void write_hdr_image(const std::filesystem::path& file, const FrameBuffer& frame) {
  const std::string ext = extension_of(file);
  if (ext == ".pfm") return write_pfm(file, frame);
#if defined(COHORT_HAVE_OIIO)
  write_with_oiio(file, frame.width, frame.height, 4, OIIO::TypeDesc::FLOAT, frame.rgba.data());
#else
  throw std::runtime_error(fmt::format("{}: this build has no OpenImageIO; write .pfm instead", file.string()));
#endif
}

FrameBuffer read_pfm(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open", file.string()));
  std::string magic;
  int width = 0, height = 0;
  float scale = 0.0f;
  in >> magic >> width >> height >> scale;
  in.get();
  if (!in || (magic != "PF" && magic != "Pf") || width <= 0 || height <= 0 || width > 65536 || height > 65536)
    throw std::runtime_error(fmt::format("{}: not a PFM image this reader understands", file.string()));
  if (scale > 0.0f) throw std::runtime_error(fmt::format("{}: big-endian PFM is not supported", file.string()));
  const int channels = magic == "PF" ? 3 : 1;
  FrameBuffer frame;
  frame.resize(width, height);
  std::vector<float> row(size_t(width) * channels);
  for (int y = height - 1; y >= 0; --y) {
    in.read(reinterpret_cast<char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
    if (!in) throw std::runtime_error(fmt::format("{}: truncated at row {}", file.string(), height - 1 - y));
    float* dst = frame.row(y);
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 4; ++c) dst[x * 4 + c] = c < 3 ? row[size_t(x) * channels + (channels == 3 ? c : 0)] : 1.0f;
  }
  return frame;
}

}  // namespace cohort::core
