#include "cohort/scene/image_decode.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#ifdef COHORT_HAVE_OIIO
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#endif

namespace cohort::scene {

namespace {

std::string extension_of(const std::string& name) {
  auto dot = name.find_last_of('.');
  if (dot == std::string::npos || name.find('/', dot) != std::string::npos) return "";
  std::string ext = name.substr(dot + 1);
  for (char& c : ext)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return ext;
}

#ifdef COHORT_HAVE_OIIO
std::optional<Image> read_with(OIIO::ImageInput& in, std::string& error) {
  const OIIO::ImageSpec& spec = in.spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.nchannels > 64 ||
      static_cast<long long>(spec.width) * spec.height > kMaxImagePixels) {
    error = "bad image size " + std::to_string(spec.width) + "x" + std::to_string(spec.height);
    return std::nullopt;
  }
  const int channels = spec.nchannels;
  std::vector<uint8_t> pixels(static_cast<size_t>(spec.width) * spec.height * channels);
  if (!in.read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, pixels.data())) {
    error = in.geterror();
    return std::nullopt;
  }
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.rgba.resize(static_cast<size_t>(spec.width) * spec.height * 4);
  for (size_t i = 0, n = static_cast<size_t>(spec.width) * spec.height; i < n; ++i) {
    const uint8_t* p = &pixels[i * channels];
    uint8_t* o = &image.rgba[i * 4];
    if (channels == 1) { o[0] = o[1] = o[2] = p[0]; o[3] = 255; }
    else if (channels == 2) { o[0] = o[1] = o[2] = p[0]; o[3] = p[1]; }
    else { o[0] = p[0]; o[1] = p[1]; o[2] = p[2]; o[3] = channels >= 4 ? p[3] : 255; }
  }
  return image;
}

std::optional<Image> decode_with_oiio(std::string_view bytes, const std::string& ext, std::string& error) {
  OIIO::Filesystem::IOMemReader reader(const_cast<char*>(bytes.data()), bytes.size());
  OIIO::ImageSpec config;
  auto in = OIIO::ImageInput::open("memory." + ext, &config, &reader);
  if (in) return read_with(*in, error);
  // Some format plugins cannot read from memory; they get a temporary file.
  OIIO::geterror();
  std::error_code ec;
  auto path = std::filesystem::temp_directory_path(ec) /
              ("cohort-image-" + std::to_string(::getpid()) + "-" + std::to_string(reinterpret_cast<uintptr_t>(bytes.data())) + "." + ext);
  {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  auto file_in = OIIO::ImageInput::open(path.string());
  std::optional<Image> image;
  if (file_in) {
    image = read_with(*file_in, error);
    file_in->close();
  } else {
    error = OIIO::geterror();
    if (error.empty()) error = "OpenImageIO cannot read it";
  }
  std::filesystem::remove(path, ec);
  return image;
}
#endif

}  // namespace

bool is_rxgb_dds(std::string_view bytes) {
  return bytes.size() >= 128 && bytes.substr(0, 4) == "DDS " && bytes.substr(84, 4) == "RXGB";
}

std::optional<Image> decode_image(std::string_view bytes, const std::string& file_name, std::string& error) {
  const std::string ext = extension_of(file_name);
#ifdef COHORT_HAVE_OIIO
  if (is_rxgb_dds(bytes)) {
    // RXGB is DXT5 with X moved into alpha; decode it as DXT5 and move X back into red.
    std::string patched(bytes);
    std::memcpy(&patched[84], "DXT5", 4);
    auto image = decode_with_oiio(patched, "dds", error);
    if (image) {
      for (size_t i = 0; i < image->rgba.size(); i += 4) {
        image->rgba[i] = image->rgba[i + 3];
        image->rgba[i + 3] = 255;
      }
      image->is_normal_map = true;
    }
    return image;
  }
  std::string oiio_error;
  if (auto image = decode_with_oiio(bytes, ext.empty() ? "tga" : ext, oiio_error)) return image;
  if (ext == "tga") return decode_tga(bytes, error);
  error = oiio_error;
  return std::nullopt;
#else
  if (ext == "tga") return decode_tga(bytes, error);
  error = "." + ext + " images need OpenImageIO (this build has only the TGA reader)";
  return std::nullopt;
#endif
}

}  // namespace cohort::scene
