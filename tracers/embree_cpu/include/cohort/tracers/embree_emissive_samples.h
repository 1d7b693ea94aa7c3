// The point of each picked emissive triangle and the BRDF toward it (kernel/emissive_sample.h's
// k_emissive_sample_point) for many vertices at once, eight to an instruction stream, for the Embree tracer's
// wavefront: after the stage's picks (embree_emissive_picks.h) every lit vertex's sample is pure arithmetic on
// its surface, its pick's triangle and two random numbers, with four early outs and two square roots and four
// divisions in a chain; eight side by side overlap those latencies and the outs become masks. Per lane, the
// same operations in the same order as the portable function (EmbreeEmissiveSamples.* compares bit for bit in a
// build without FMA contraction; both of the tracer's tile renderers sample through here, so their images stay
// equal where the compiler contracts multiply-adds).
#pragma once

#include "cohort/kernel/emissive_sample.h"
#include "cohort/kernel/lit_vertex.h"
#include "cohort/tracers/embree_emissive_picks.h"

namespace cohort::tracers::embree_emissive {

struct V3 {
  F8 x, y, z;
};

static inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline V3 operator*(V3 a, F8 s) { return {a.x * s, a.y * s, a.z * s}; }
static inline V3 operator*(V3 a, V3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
static inline F8 dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline V3 cross(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static inline F8 max_component(V3 a) { return fmax8(a.x, fmax8(a.y, a.z)); }
static inline F8 saturate(F8 x) { return fmin8(fmax8(x, splat(0.0f)), splat(1.0f)); }
static inline V3 select(I8 m, V3 a, V3 b) { return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z}; }

static inline F8 sqrt8(F8 x) {
#if defined(__AVX2__)
  return (F8)_mm256_sqrt_ps((__m256)x);
#else
  F8 r;
  for (int k = 0; k < 8; ++k) r[k] = k_sqrt(x[k]);
  return r;
#endif
}

// brdf.h's k_brdf_eval_cos(sf, wo, wi, 1) per lane (spec_scale 1 is above 0: the specular lobe wherever the
// surface has specular).
static inline V3 brdf_eval_cos(V3 n, V3 geo, V3 albedo, V3 specular, F8 roughness, V3 wo, V3 wi) {
  const F8 n_dot_l = dot(n, wi);
  const I8 zero = (n_dot_l <= 0.0f) | (dot(geo, wi) <= 0.0f);
  const F8 n_dot_v = fmax8(dot(n, wo), splat(1e-4f));
  V3 result = albedo * (n_dot_l / K_PI);
  const I8 spec = max_component(specular) > 0.0f;
  const V3 sum = wi + wo;
  const F8 length = sqrt8(dot(sum, sum));
  const V3 h = select(length > 0.0f, sum * (splat(1.0f) / length), V3{splat(0.0f), splat(0.0f), splat(1.0f)});
  const F8 n_dot_h = saturate(dot(n, h));
  const F8 v_dot_h = saturate(dot(wo, h));
  const F8 r = fmax8(roughness, splat(K_MIN_ROUGHNESS));
  const F8 alpha = r * r;
  const F8 a2 = alpha * alpha;
  const F8 dd = n_dot_h * n_dot_h * (a2 - 1.0f) + 1.0f;
  const F8 d = a2 / (K_PI * dd * dd);
  const F8 k = alpha * 0.5f;
  const F8 g = n_dot_l / (n_dot_l * (1.0f - k) + k) * (n_dot_v / (n_dot_v * (1.0f - k) + k));
  const F8 m = saturate(1.0f - v_dot_h);
  const F8 m5 = m * m * m * m * m;
  const V3 fresnel = specular + (V3{splat(1.0f), splat(1.0f), splat(1.0f)} - specular) * m5;
  const V3 with_spec = result + fresnel * (1.0f * d * g / (4.0f * n_dot_v));
  result = select(spec, with_spec, result);
  return select(zero, V3{splat(0.0f), splat(0.0f), splat(0.0f)}, result);
}

// What a lane reads: the vertex's surface and wo, the triangle's corners, the numbers and the pick's probability.
enum Input {
  kPos, kNormal = kPos + 3, kGeo = kNormal + 3, kAlbedo = kGeo + 3, kSpecular = kAlbedo + 3, kWo = kSpecular + 3,
  kP0 = kWo + 3, kP1 = kP0 + 3, kP2 = kP1 + 3, kRoughness = kP2 + 3, kU1, kU2, kProb, kInputs
};

static inline void put(float (*in)[8], int at, int k, KVec3 v) {
  in[at][k] = v.x;
  in[at + 1][k] = v.y;
  in[at + 2][k] = v.z;
}

static inline void put(float (*in)[8], int at, int k, const float* v) {
  in[at][k] = v[0];
  in[at + 1][k] = v[1];
  in[at + 2][k] = v[2];
}

static inline F8 load(const float* lanes) {
  F8 v;
  __builtin_memcpy(&v, lanes, sizeof v);
  return v;
}

static inline V3 load3(float (*in)[8], int at) { return {load(in[at]), load(in[at + 1]), load(in[at + 2])}; }

// Up to eight samples: lanes [0, lanes). The inputs go through a table of lanes written by scalar stores (each
// vector then one load): lane inserts into vectors compiled to a copy through the stack per value.
static inline void samples8(const KSceneView* scene, int lanes, const KLitVertex* const* vertices,
                            const KEmissivePick* picks, const float* u1s, const float* u2s, KEmissiveSample* out) {
  alignas(32) float in[kInputs][8];
  I8 alive{};
  for (int k = 0; k < 8; ++k) {
    if (k >= lanes || picks[k].index == K_NONE || !(picks[k].prob > 0.0f)) {
      for (int i = 0; i < kInputs; ++i) in[i][k] = 0.0f;
      continue;
    }
    const KSurface& sf = vertices[k]->sf;
    const KEmissiveTriangle& e = scene->emissive[picks[k].index];
    alive[k] = -1;
    put(in, kPos, k, sf.position);
    put(in, kNormal, k, sf.normal);
    put(in, kGeo, k, sf.geo_normal);
    put(in, kAlbedo, k, sf.albedo);
    put(in, kSpecular, k, sf.specular);
    put(in, kWo, k, vertices[k]->wo);
    put(in, kP0, k, e.p0);
    put(in, kP1, k, e.p1);
    put(in, kP2, k, e.p2);
    in[kRoughness][k] = sf.roughness;
    in[kU1][k] = u1s[k];
    in[kU2][k] = u2s[k];
    in[kProb][k] = picks[k].prob;
  }
  const V3 pos = load3(in, kPos), n = load3(in, kNormal), geo = load3(in, kGeo), albedo = load3(in, kAlbedo);
  const V3 specular = load3(in, kSpecular), wo = load3(in, kWo);
  const V3 p0 = load3(in, kP0), p1 = load3(in, kP1), p2 = load3(in, kP2);
  const F8 roughness = load(in[kRoughness]), u1 = load(in[kU1]), u2 = load(in[kU2]), prob = load(in[kProb]);
  const F8 su = sqrt8(u1);
  const F8 bu = su * (1.0f - u2), bv = su * u2;
  const V3 x = p0 * (1.0f - bu - bv) + (p1 * bu + p2 * bv);
  const V3 cr = cross(p1 - p0, p2 - p0);
  const F8 double_area = sqrt8(dot(cr, cr));
  alive &= double_area > 0.0f;
  const V3 to_light = x - pos;
  const F8 dist2 = dot(to_light, to_light);
  alive &= dist2 > 0.0f;
  const F8 dist = sqrt8(dist2);
  const V3 wi = to_light * (1.0f / dist);
  const F8 cos_light = (F8)((I8)dot(cr, wi) & 0x7fffffff) / double_area;  // k_fabs: the sign bit cleared
  alive &= ~(cos_light <= 1e-6f);
  const V3 f = brdf_eval_cos(n, geo, albedo, specular, roughness, wo, wi);
  alive &= ~(max_component(f) <= 0.0f);
  const F8 pdf = prob * 2.0f / double_area * dist2 / cos_light;
  for (int k = 0; k < lanes; ++k) {
    KEmissiveSample& s = out[k];
    if (!alive[k]) {
      s.index = K_NONE;
      continue;
    }
    s.x = v3(x.x[k], x.y[k], x.z[k]);
    s.wi = v3(wi.x[k], wi.y[k], wi.z[k]);
    s.f = v3(f.x[k], f.y[k], f.z[k]);
    s.bu = bu[k];
    s.bv = bv[k];
    s.pdf = pdf[k];
    s.index = picks[k].index;
  }
}

// k_emissive_sample_point(scene, &vertices[i]->sf, vertices[i]->wo, picks[i].index, picks[i].prob, u1s[i],
// u2s[i], &out[i]) for each of the n vertices.
static inline void samples(const KSceneView* scene, int n, const KLitVertex* const* vertices, const KEmissivePick* picks,
                           const float* u1s, const float* u2s, KEmissiveSample* out) {
  for (int first = 0; first < n; first += 8)
    samples8(scene, n - first < 8 ? n - first : 8, vertices + first, picks + first, u1s + first, u2s + first,
             out + first);
}

}  // namespace cohort::tracers::embree_emissive
