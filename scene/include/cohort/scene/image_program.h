// Image programs as materials write them: a plain image path, or a function of images and numbers
// such as addnormals(textures/a_local, heightmap(textures/a_h, 4)).
#pragma once

#include <string>
#include <vector>

#include "cohort/scene/lexer.h"

namespace cohort::scene {

struct ImageProgram {
  std::string function;               // lower case; empty for a plain image
  std::string path;                   // the image name for a plain image
  std::vector<ImageProgram> inputs;   // image arguments, in order
  std::vector<float> numbers;         // numeric arguments, in order

  bool empty() const { return function.empty() && path.empty(); }
  // Canonical text: the cache key and the Image::name of the result.
  std::string text() const;
};

// Reads one image program; ParseError when it is malformed.
ImageProgram parse_image_program(Lexer& lex);

}  // namespace cohort::scene
