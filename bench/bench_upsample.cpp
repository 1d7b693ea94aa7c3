// Host cost of dynamic resolution's reconstruction (core/upsample.h): the joint-bilateral and nearest
// reconstructions of a sparse frame, and the bilinear stretch of a frame at the render scale, on a
// synthetic G-buffer (walls at a few depths and normals, a textured albedo, an object), median of --frames.
//   bench_upsample [--width 640] [--height 360] [--scale 0.5] [--frames 20]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "cohort/balance/order_statistics.h"
#include "cohort/core/host_threads.h"
#include "cohort/core/upsample.h"

using namespace cohort::core;

namespace {

template <typename F>
double median_ms(int frames, F&& run) {
  std::vector<double> ms;
  for (int f = 0; f < frames; ++f) {
    const auto start = std::chrono::steady_clock::now();
    run(f);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  return cohort::median(ms);
}

}  // namespace

int main(int argc, char** argv) {
  int width = 640, height = 360, frames = 20;
  double scale = 0.5;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--width") width = std::stoi(argv[i + 1]);
    else if (arg == "--height") height = std::stoi(argv[i + 1]);
    else if (arg == "--scale") scale = std::stod(argv[i + 1]);
    else if (arg == "--frames") frames = std::max(1, std::stoi(argv[i + 1]));
    else {
      std::fprintf(stderr, "bench_upsample: unknown option %s\n", arg.c_str());
      return 2;
    }
  }
  FrameBuffer sparse, out, low;
  sparse.resize(width, height);
  GBuffer g;
  g.resize(width, height);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t p = size_t(y) * width + x;
      const int wall = (x * 4 / width + y * 3 / height) % 3;
      g.depth[p] = y < height / 8 ? 0.0f : 100.0f + 50.0f * wall + 0.1f * x;
      g.normal[3 * p + wall] = 1.0f;
      for (int k = 0; k < 3; ++k) g.albedo[3 * p + k] = 0.2f + 0.6f * u(rng), sparse.rgba[4 * p + k] = 2.0f * u(rng);
      g.id[p] = x > width / 2 && y > height / 2 ? 3u : 0u;
    }
  const int low_w = std::max(1, int(width * scale + 0.5)), low_h = std::max(1, int(height * scale + 0.5));
  low.resize(low_w, low_h);
  const double joint = median_ms(frames, [&](int f) {
    upsample_sparse(sparse, g, path_pattern_for_scale(scale, uint64_t(f)), UpsampleMethod::joint_bilateral, out);
  });
  const double nearest = median_ms(frames, [&](int f) {
    upsample_sparse(sparse, g, path_pattern_for_scale(scale, uint64_t(f)), UpsampleMethod::nearest, out);
  });
  const double bilinear = median_ms(frames, [&](int) { stretch_bilinear(low, width, height, out); });
  std::printf("%dx%d at scale %.2f (%u of 16 pixels traced), %u host threads, median of %d frames\n", width, height,
              scale, path_pattern_for_scale(scale, 0).pixels, HostThreads::shared().threads(), frames);
  std::printf("joint-bilateral %.2f ms   nearest %.2f ms   bilinear stretch %.2f ms\n", joint, nearest, bilinear);
  return 0;
}
