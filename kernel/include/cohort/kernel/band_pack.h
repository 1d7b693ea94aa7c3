/* A band's colour in 32 bits a pixel (core's BandFormat::rgb9e5): three 9-bit mantissas under one 5-bit
 * exponent, laid out as GL_RGB9_E5 / DXGI R9G9B9E5_SHAREDEXP (red in bits 0-8, green 9-17, blue 18-26,
 * the exponent in 27-31, bias 15). Written once here for every producer (the CUDA and OpenCL packing
 * kernels, the host's BandBuffer for Embree and the node) and the decoders (the host's merge, the CUDA
 * post).
 *
 * Why shared exponent rather than R11G11B10F: the brightest channel keeps 9 bits (R11G11B10F keeps 6 for
 * red and green and 5 for blue), so a channel's error is under 1/255.5 of its pixel's brightest one; a
 * darker channel of a strongly tinted pixel loses relative precision, which the dither below keeps
 * unbiased (docs/cluster.md, "Bands at 4 bytes a pixel", has the numbers for both).
 *
 * Rounding: a rounded mantissa is biased for a channel well below the brightest (1.4 of 511 steps
 * always reads 1), and Brigade's blend and the reprojection average the same pixel over many frames, so
 * the bias would stay in the image. Each channel rounds up with probability equal to its fraction
 * (stochastic rounding) from a hash of the pixel and the frame: the mean of many frames' encodings is
 * the input. The exponent is chosen from the brightest channel alone, so that choice does not depend on
 * the dither and each channel's rounding stays unbiased.
 *
 * Non-finite input: a pixel with any NaN or infinite channel is stored as K_RGB9E5_NONFINITE, which
 * decodes to NaN in all three channels, so the history's rejection of non-finite samples still sees it.
 * Finite values clamp to [0, K_RGB9E5_MAX]: negative radiance is not a colour, and the largest mantissa
 * at the largest exponent is 510, so no finite pixel encodes as the reserved all-ones word. */
#ifndef COHORT_KERNEL_BAND_PACK_H
#define COHORT_KERNEL_BAND_PACK_H
#include "portable.h"
#include "rng.h"

#define K_RGB9E5_NONFINITE 0xffffffffu
/* 510 * 2^(31 - 15 - 9): one step below GL's 65408, whose all-ones word here means "not finite". */
#define K_RGB9E5_MAX 65280.0f

/* A channel clamped to [0, K_RGB9E5_MAX] (NaN handled by the caller); written with selects so the
 * compiler keeps the host's loop free of branches. */
KFN float k_rgb9e5_clamp(float v) {
  v = v > 0.0f ? v : 0.0f;
  return v < K_RGB9E5_MAX ? v : K_RGB9E5_MAX;
}

/* Whether a float is NaN or infinite, from its bits (fast-math compilers may fold v != v away). */
KFN int k_rgb9e5_nonfinite(float v) { return (k_as_uint(v) & 0x7f800000u) == 0x7f800000u; }

/* One channel's mantissa at scale 2^-(exponent - 24): floor(v * scale + dither), dither in [0, 1). The sum
 * is never negative, so the conversion's truncation is the floor (floorf is a libm call on x86-64 without
 * SSE4.1: 35 ms a 1080p frame on the host with it, against the conversion's few). */
KFN kuint k_rgb9e5_mantissa(float v, float inv_scale, float dither) {
  return (kuint)(v * inv_scale + dither);
}

/* Packs one pixel; dither in [0, 1) (k_rgb9e5_dither), 0.5 for round to nearest (ties up). Written without
 * early returns or branches (selects throughout), so that the host's loop over a row vectorises. */
KFN kuint k_rgb9e5_encode(float r, float g, float b, float dither) {
  const int nonfinite = k_rgb9e5_nonfinite(r) | k_rgb9e5_nonfinite(g) | k_rgb9e5_nonfinite(b);
  r = k_rgb9e5_clamp(r);
  g = k_rgb9e5_clamp(g);
  b = k_rgb9e5_clamp(b);
  float top = r > g ? r : g;
  top = top > b ? top : b;
  /* The exponent e puts the brightest channel's mantissa in [256, 512): e = floor(log2(top)) + 1 + 15,
   * read off the float's own exponent field; 0 for anything below 2^-16 (subnormals and zero too). */
  kint e = (kint)((k_as_uint(top) >> 23) & 0xffu) - 111;
  e = e > 0 ? e : 0;
  e = e < 31 ? e : 31;
  /* 2^(24 - e), built from its bits (always a normal float for e in [0, 31]): the products are exact. A
   * mantissa above 511 could round up to 512: that takes the next exponent instead, decided from the
   * brightest channel alone so that the dither does not choose the scale. */
  const int next = (top * k_bits_to_float((kuint)(151 - e) << 23) > 511.0f) & (e < 31);
  e += next ? 1 : 0;
  const float inv_scale = k_bits_to_float((kuint)(151 - e) << 23);
  /* One dither for the three channels: each channel's rounding is unbiased on its own, and their errors
   * go the same way (a pixel a little brighter or darker, rather than a tint). */
  kuint mr = k_rgb9e5_mantissa(r, inv_scale, dither);
  kuint mg = k_rgb9e5_mantissa(g, inv_scale, dither);
  kuint mb = k_rgb9e5_mantissa(b, inv_scale, dither);
  /* The float sum of a mantissa near 511 and a dither near 1 may round to 512: keep to 9 bits. */
  mr = mr < 511u ? mr : 511u;
  mg = mg < 511u ? mg : 511u;
  mb = mb < 511u ? mb : 511u;
  kuint word = mr | (mg << 9) | (mb << 18) | ((kuint)e << 27);
  /* Only that float rounding at the top exponent could spell the reserved word: one step down in red. */
  word = word == K_RGB9E5_NONFINITE ? word - 1u : word;
  return nonfinite ? K_RGB9E5_NONFINITE : word;
}

/* The dither of pixel `pixel` (y * width + x over the whole frame) in frame `frame`: uniform in [0, 1),
 * the same on every device, and independent of the integrator's own random numbers (a salt of its own). */
KFN float k_rgb9e5_dither(kuint pixel, kuint frame) {
  const kuint h = k_pcg_hash(pixel ^ k_pcg_hash(frame ^ 0x9e3779b9u));
  return (float)(h >> 8) * (1.0f / 16777216.0f);
}

/* One channel of a packed pixel: 0 red, 1 green, 2 blue. The reserved word decodes to NaN. */
KFN float k_rgb9e5_channel(kuint packed, kuint channel) {
  if (packed == K_RGB9E5_NONFINITE) return k_bits_to_float(0x7fc00000u);
  const kuint e = packed >> 27;
  const float scale = k_bits_to_float((e + 103u) << 23); /* 2^(e - 15 - 9) */
  return (float)((packed >> (9u * channel)) & 511u) * scale;
}

#endif
