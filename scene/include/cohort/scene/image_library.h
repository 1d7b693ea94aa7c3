// Loads the images materials name into Scene::images, once each: finds the file the way the engine
// does (the name as given, then .tga, .png, .jpg, .dds and dds/<name>.dds), runs image programs, and
// puts a visible placeholder (with a warning) where a file is missing or unreadable.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "cohort/scene/cube_map.h"
#include "cohort/scene/image_program.h"
#include "cohort/scene/scene.h"
#include "cohort/scene/vfs.h"

namespace cohort::scene {

// What an image is for; it picks the placeholder (checker for colour, flat for normals, black for
// specular, white for light falloff) and marks normal maps.
enum class ImageRole : uint8_t { Color, Normal, Specular, LightProjection, LightFalloff };

class ImageLibrary {
 public:
  ImageLibrary(const Vfs& vfs, std::vector<Image>& images, std::vector<std::string>& warnings);

  // Index into the images vector; always a valid image. `context` prefixes warnings ("material x").
  int get(const ImageProgram& program, ImageRole role, const std::string& context);
  // A cube map's six faces as six consecutive images (GL order +X, -X, +Y, -Y, +Z, -Z); returns the
  // first one's index. A face that is missing, unreadable, not square or not the size of the others
  // fails the whole cube, as in the engine: a warning naming the face, and six placeholder faces.
  int get_cube(const std::string& name, CubeMapKind kind, const std::string& context);
  // A warning about an image a material uses that is not a load failure ("file:line: material x: ...").
  void warn(std::string message) { warnings_.push_back(std::move(message)); }
  // Whether a plain image of that name can be found (for materials named after an image).
  bool can_find(const std::string& name) const;

  int loaded_count() const { return loaded_; }
  int placeholder_count() const { return placeholders_; }

 private:
  std::optional<Image> evaluate(const ImageProgram& program, ImageRole role, std::string& error);
  std::optional<Image> load_file(const std::string& name, std::string& error);
  std::optional<std::string> find_file(const std::string& name) const;

  const Vfs& vfs_;
  std::vector<Image>& images_;
  std::vector<std::string>& warnings_;
  std::map<std::string, int> by_key_;
  int loaded_ = 0, placeholders_ = 0;
};

// Built-in and placeholder images.
Image solid_image(const std::string& name, uint8_t r, uint8_t g, uint8_t b, uint8_t a);
Image checker_image(const std::string& name);
Image placeholder_for(ImageRole role, const std::string& name);

}  // namespace cohort::scene
