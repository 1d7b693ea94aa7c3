#include "cohort/scene/image_library.h"

#include "cohort/scene/image_decode.h"
#include "cohort/scene/image_ops.h"
#include "ascii_case.h"

namespace cohort::scene {

namespace {

constexpr const char* kExtensions[] = {".tga", ".png", ".jpg", ".jpeg", ".dds", ".bmp"};

std::string strip_extension(const std::string& name) {
  std::string lower = lowercase(name);
  for (const char* ext : kExtensions) {
    std::string e(ext);
    if (lower.size() > e.size() && lower.compare(lower.size() - e.size(), e.size(), e) == 0)
      return name.substr(0, name.size() - e.size());
  }
  return name;
}

}  // namespace

Image solid_image(const std::string& name, uint8_t r, uint8_t g, uint8_t b, uint8_t a) {
  Image image;
  image.name = name;
  image.width = image.height = 1;
  image.rgba = {r, g, b, a};
  return image;
}

Image checker_image(const std::string& name) {
  Image image;
  image.name = name;
  image.width = image.height = 8;
  image.rgba.resize(8 * 8 * 4);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      uint8_t* p = &image.rgba[(y * 8 + x) * 4];
      bool magenta = ((x / 4) + (y / 4)) % 2 == 0;
      p[0] = magenta ? 255 : 0;
      p[1] = 0;
      p[2] = magenta ? 255 : 0;
      p[3] = 255;
    }
  return image;
}

Image placeholder_for(ImageRole role, const std::string& name) {
  Image image;
  switch (role) {
    case ImageRole::Normal: image = solid_image(name, 128, 128, 255, 255); image.is_normal_map = true; break;
    case ImageRole::Specular: image = solid_image(name, 0, 0, 0, 255); break;
    case ImageRole::LightFalloff: image = solid_image(name, 255, 255, 255, 255); break;
    default: image = checker_image(name); break;
  }
  image.is_placeholder = true;
  return image;
}

ImageLibrary::ImageLibrary(const Vfs& vfs, std::vector<Image>& images, std::vector<std::string>& warnings)
    : vfs_(vfs), images_(images), warnings_(warnings) {}

std::optional<std::string> ImageLibrary::find_file(const std::string& name) const {
  if (vfs_.exists(name)) return name;
  std::string base = strip_extension(name);
  for (const char* ext : kExtensions)
    if (vfs_.exists(base + ext)) return base + ext;
  if (vfs_.exists("dds/" + base + ".dds")) return "dds/" + base + ".dds";
  return std::nullopt;
}

bool ImageLibrary::can_find(const std::string& name) const { return find_file(name).has_value(); }

std::optional<Image> ImageLibrary::load_file(const std::string& name, std::string& error) {
  std::string lower = lowercase(name);
  if (lower == "_white") return solid_image(name, 255, 255, 255, 255);
  if (lower == "_black") return solid_image(name, 0, 0, 0, 255);
  if (lower == "_flat") {
    Image flat = solid_image(name, 128, 128, 255, 255);
    flat.is_normal_map = true;
    return flat;
  }
  if (lower == "_default") return checker_image(name);
  auto file = find_file(name);
  if (!file) {
    error = "image not found";
    return std::nullopt;
  }
  std::optional<std::string> bytes;
  try {
    bytes = vfs_.read(*file);
  } catch (const std::exception& e) {
    error = e.what();
    return std::nullopt;
  }
  if (!bytes) {
    error = "image not found";
    return std::nullopt;
  }
  auto image = decode_image(*bytes, *file, error);
  if (image) error.clear();
  else error = vfs_.describe(*file) + ": " + error;
  return image;
}

std::optional<Image> ImageLibrary::evaluate(const ImageProgram& program, ImageRole role, std::string& error) {
  if (program.function.empty()) return load_file(program.path, error);
  std::vector<Image> inputs;
  for (const ImageProgram& input : program.inputs) {
    auto image = evaluate(input, role, error);
    if (!image) return std::nullopt;
    inputs.push_back(std::move(*image));
  }
  auto number = [&](size_t i, float fallback) { return i < program.numbers.size() ? program.numbers[i] : fallback; };
  const std::string& f = program.function;
  if (f == "heightmap") return heightmap_to_normals(inputs[0], number(0, 1.0f));
  if (f == "addnormals" && inputs.size() >= 2) return add_normals(inputs[0], inputs[1]);
  if (f == "smoothnormals") return smooth_normals(inputs[0]);
  if (f == "add" && inputs.size() >= 2) return add_images(inputs[0], inputs[1]);
  if (f == "scale") {
    float factors[4] = {number(0, 1.0f), number(1, 1.0f), number(2, 1.0f), number(3, 1.0f)};
    return scale_channels(inputs[0], factors);
  }
  if (f == "invertalpha") return invert_alpha(inputs[0]);
  if (f == "invertcolor") return invert_color(inputs[0]);
  if (f == "makeintensity") return make_intensity(inputs[0]);
  if (f == "makealpha") return make_alpha(inputs[0]);
  if (f == "downsize") return std::move(inputs[0]);   // full resolution is kept
  error = f + "() with " + std::to_string(inputs.size()) + " images is not a known image program";
  return std::nullopt;
}

int ImageLibrary::get(const ImageProgram& program, ImageRole role, const std::string& context) {
  const std::string name = program.text();
  const std::string key = lowercase(name) + "#" + std::to_string(static_cast<int>(role));
  auto cached = by_key_.find(key);
  if (cached != by_key_.end()) return cached->second;
  std::string error;
  std::optional<Image> image = evaluate(program, role, error);
  if (image && !image->rgba.empty()) {
    ++loaded_;
  } else {
    warnings_.push_back(context + ": image '" + name + "': " + (error.empty() ? "empty image" : error) +
                        "; using a placeholder");
    image = placeholder_for(role, name);
    ++placeholders_;
  }
  image->name = strip_extension(name);
  if (role == ImageRole::Normal) image->is_normal_map = true;
  int index = static_cast<int>(images_.size());
  images_.push_back(std::move(*image));
  by_key_[key] = index;
  return index;
}

int ImageLibrary::get_cube(const std::string& name, CubeMapKind kind, const std::string& context) {
  const std::string base = strip_extension(name);
  const std::string key = lowercase(base) + (kind == CubeMapKind::Camera ? "#cameracube" : "#cube");
  auto cached = by_key_.find(key);
  if (cached != by_key_.end()) return cached->second;
  std::vector<Image> faces;
  std::string error;
  for (int face = 0; face < 6 && error.empty(); ++face) {
    const std::string face_name = base + cube_face_suffix(kind, face);
    std::optional<Image> image = load_file(face_name, error);
    if (!image || image->rgba.empty()) {
      error = "face '" + face_name + "': " + (error.empty() ? "empty image" : error);
    } else if (image->width != image->height) {
      error = "face '" + face_name + "' is " + std::to_string(image->width) + "x" + std::to_string(image->height) +
              ", not square";
    } else if (!faces.empty() && image->width != faces.front().width) {
      error = "face '" + face_name + "' is " + std::to_string(image->width) + " wide, face '" + base +
              cube_face_suffix(kind, 0) + "' " + std::to_string(faces.front().width);
    } else {
      image->name = face_name;
      faces.push_back(kind == CubeMapKind::Camera ? camera_image_to_cube_face(*image, face) : std::move(*image));
    }
  }
  if (!error.empty()) {
    warnings_.push_back(context + ": cube map '" + base + "': " + error + "; using placeholder faces");
    faces.clear();
    for (int face = 0; face < 6; ++face)
      faces.push_back(placeholder_for(ImageRole::Color, base + cube_face_suffix(kind, face)));
    placeholders_ += 6;
  } else {
    loaded_ += 6;
  }
  const int first = static_cast<int>(images_.size());
  for (Image& face : faces) images_.push_back(std::move(face));
  by_key_[key] = first;
  return first;
}

}  // namespace cohort::scene
