// How a GPU tracer's wavefront splits a band into lanes of rows, each lane's kernels on a queue or stream of
// its own, so that one lane's kernels fill the GPU while another's last wave drains (docs/balancing.md,
// "Four GPUs"). One rule for the CUDA and the OpenCL tracers: lanes of whole 8-row work groups (a lane's last
// group must not reach into the next lane's rows), at least kMinWaveLaneRows each, the last lane taking
// the rest.
#pragma once

namespace cohort::tracers {

constexpr unsigned kMinWaveLaneRows = 32;

// The lanes a band of `rows` runs in: at most `most` (at least 1).
inline int wave_lane_count(int most, unsigned rows) {
  const int fit = static_cast<int>(rows / kMinWaveLaneRows);
  const int lanes = most < fit ? most : fit;
  return lanes > 1 ? lanes : 1;
}

// Lane `lane`'s first row, relative to the band; lane == lanes gives `rows`, the last lane's end.
inline unsigned wave_lane_first_row(unsigned rows, int lanes, int lane) {
  if (lane >= lanes) return rows;
  return rows * static_cast<unsigned>(lane) / static_cast<unsigned>(lanes) / 8u * 8u;
}

}  // namespace cohort::tracers
