// The image-program functions of idTech 4 materials, applied to decoded RGBA8 images.
#pragma once

#include "cohort/scene/scene.h"

namespace cohort::scene {

// A grey height map (mean of RGB) to a tangent-space normal map (X in R, Y in G, Z in B), with the
// engine's convention that `scale` is the bump height of a full-white texel.
Image heightmap_to_normals(const Image& height, float scale);
// Sum of two normal maps, renormalized; `b` is resampled (nearest) to `a`'s size if they differ.
Image add_normals(const Image& a, const Image& b);
// A 3x3 average of a normal map, renormalized.
Image smooth_normals(const Image& normals);
// Channel-wise a + b, clamped; `b` resampled to `a`'s size.
Image add_images(const Image& a, const Image& b);
Image scale_channels(const Image& image, const float factors[4]);
Image invert_alpha(const Image& image);
Image invert_color(const Image& image);
Image make_intensity(const Image& image);   // R copied into G, B and A
Image make_alpha(const Image& image);       // alpha = mean of RGB, RGB white

}  // namespace cohort::scene
