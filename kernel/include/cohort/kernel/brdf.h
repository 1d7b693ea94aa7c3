/* Lambert diffuse plus Cook-Torrance specular: GGX distribution, Smith-Schlick geometry term,
 * Schlick Fresnel. All directions point away from the surface; n is the shading normal. */
#ifndef COHORT_KERNEL_BRDF_H
#define COHORT_KERNEL_BRDF_H
#include "material.h"

#define K_MIN_ROUGHNESS 0.03f

KFN float k_ggx_d(float n_dot_h, float alpha) {
  float a2 = alpha * alpha;
  float d = n_dot_h * n_dot_h * (a2 - 1.0f) + 1.0f;
  return a2 / (K_PI * d * d);
}

/* Schlick's approximation of Smith's masking with k = alpha / 2 (the GGX match). */
KFN float k_smith_schlick_g1(float n_dot_x, float alpha) {
  float k = alpha * 0.5f;
  return n_dot_x / (n_dot_x * (1.0f - k) + k);
}

KFN KVec3 k_fresnel_schlick(KVec3 f0, float v_dot_h) {
  float m = k_saturate(1.0f - v_dot_h);
  float m5 = m * m * m * m * m;
  return v3_add(f0, v3_scale(v3_sub(v3s(1.0f), f0), m5));
}

KFN float k_alpha_of(const KSurface* sf) {
  float r = k_fmax(sf->roughness, K_MIN_ROUGHNESS);
  return r * r;
}

/* f(wo, wi) * cos(theta_i); spec_scale is the specular boost for light interactions (1 elsewhere). */
KFN KVec3 k_brdf_eval_cos(const KSurface* sf, KVec3 wo, KVec3 wi, float spec_scale) {
  KVec3 n = sf->normal;
  float n_dot_l = v3_dot(n, wi), n_dot_v = v3_dot(n, wo);
  if (n_dot_l <= 0.0f || v3_dot(sf->geo_normal, wi) <= 0.0f) return v3s(0.0f);
  n_dot_v = k_fmax(n_dot_v, 1e-4f);
  KVec3 result = v3_scale(sf->albedo, n_dot_l / K_PI);
  if (spec_scale > 0.0f && v3_max_component(sf->specular) > 0.0f) {
    KVec3 h = v3_normalize(v3_add(wi, wo));
    float n_dot_h = k_saturate(v3_dot(n, h));
    float v_dot_h = k_saturate(v3_dot(wo, h));
    float alpha = k_alpha_of(sf);
    float d = k_ggx_d(n_dot_h, alpha);
    float g = k_smith_schlick_g1(n_dot_l, alpha) * k_smith_schlick_g1(n_dot_v, alpha);
    KVec3 f = k_fresnel_schlick(sf->specular, v_dot_h);
    result = v3_add(result, v3_scale(f, spec_scale * d * g / (4.0f * n_dot_v)));
  }
  return result;
}

/* Probability of sampling the specular lobe rather than the diffuse one. */
KFN float k_specular_lobe_probability(const KSurface* sf) {
  float ds = v3_luminance(sf->albedo), ss = v3_luminance(sf->specular);
  if (ss <= 0.0f) return 0.0f;
  if (ds <= 0.0f) return 1.0f;
  return k_clamp(ss / (ds + ss), 0.1f, 0.9f);
}

KFN float k_brdf_pdf(const KSurface* sf, KVec3 wo, KVec3 wi) {
  KVec3 n = sf->normal;
  float n_dot_l = v3_dot(n, wi);
  if (n_dot_l <= 0.0f) return 0.0f;
  float p_spec = k_specular_lobe_probability(sf);
  float pdf = (1.0f - p_spec) * n_dot_l / K_PI;
  if (p_spec > 0.0f) {
    KVec3 h = v3_normalize(v3_add(wi, wo));
    float n_dot_h = k_saturate(v3_dot(n, h));
    float v_dot_h = v3_dot(wo, h);
    if (v_dot_h > 0.0f) pdf += p_spec * k_ggx_d(n_dot_h, k_alpha_of(sf)) * n_dot_h / (4.0f * v_dot_h);
  }
  return pdf;
}

/* Samples wi from the one-sample mixture of the two lobes; returns f * cos / pdf (zero if rejected). */
KFN KVec3 k_brdf_sample(const KSurface* sf, KVec3 wo, float u_lobe, float u1, float u2, KVec3* wi) {
  KFrame frame = k_frame_from_normal(sf->normal);
  float p_spec = k_specular_lobe_probability(sf);
  if (u_lobe < p_spec) {
    float alpha = k_alpha_of(sf);
    float cos_theta = k_sqrt((1.0f - u1) / (1.0f + (alpha * alpha - 1.0f) * u1));
    float sin_theta = k_sqrt(k_fmax(0.0f, 1.0f - cos_theta * cos_theta));
    float phi = 2.0f * K_PI * u2;
    KVec3 h = k_frame_to_world(&frame, v3(sin_theta * k_cos(phi), sin_theta * k_sin(phi), cos_theta));
    *wi = v3_sub(v3_scale(h, 2.0f * v3_dot(wo, h)), wo);
  } else {
    *wi = k_frame_to_world(&frame, k_sample_cosine_hemisphere(u1, u2));
  }
  float pdf = k_brdf_pdf(sf, wo, *wi);
  if (pdf <= 1e-8f) return v3s(0.0f);
  return v3_scale(k_brdf_eval_cos(sf, wo, *wi, 1.0f), 1.0f / pdf);
}

#endif
