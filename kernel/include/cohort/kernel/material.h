/* Surface evaluation at a hit: interpolated geometry, textures, the Doom 3 material mapped to the
 * BRDF inputs, and the blend-mode classification that decides what a ray does there. */
#ifndef COHORT_KERNEL_MATERIAL_H
#define COHORT_KERNEL_MATERIAL_H
#include "texture.h"

typedef struct KSurface {
  KVec3 position;
  KVec3 geo_normal;  /* faces the incoming ray */
  KVec3 normal;      /* shading normal, in geo_normal's hemisphere */
  KVec3 albedo;      /* linear diffuse reflectance (or layer colour for non-opaque blends) */
  KVec3 specular;    /* Fresnel reflectance at normal incidence */
  KVec3 emission;
  float alpha;
  float roughness;
  float metallic;
  kuint blend;
  kuint flags;
  kuint material;
} KSurface;

KFN kuint k_hit_material(const KSceneView* scene, kuint instance, kuint triangle) {
  kuint over = scene->instances[instance].material_override;
  return over != K_NONE ? over : scene->triangles[triangle].material;
}

KFN void k_hit_st(const KSceneView* scene, kuint triangle, float u, float v, KGLOBAL const KMaterial* m,
                  float* s, float* t) {
  KTriangle tri = scene->triangles[triangle];
  KGLOBAL const KVertex* a = &scene->vertices[tri.v0];
  KGLOBAL const KVertex* b = &scene->vertices[tri.v1];
  KGLOBAL const KVertex* c = &scene->vertices[tri.v2];
  float w = 1.0f - u - v;
  float s0 = w * a->u + u * b->u + v * c->u;
  float t0 = w * a->v + u * b->v + v * c->v;
  *s = m->tex_transform[0] * s0 + m->tex_transform[1] * t0 + m->tex_transform[2];
  *t = m->tex_transform[3] * s0 + m->tex_transform[4] * t0 + m->tex_transform[5];
}

/* What a vertexColor / inverseVertexColor material multiplies its colours by at barycentrics (u, v):
 * the interpolated vertex RGBA, or (1 - RGB, 1) for inverseVertexColor (draw_arb2.cpp: colour =
 * vc * modulate + add); white for every other material. The vertex bytes multiply like a stage colour
 * (linear, not sRGB-decoded), as the stage colours in KMaterial do. */
KFN KVec4 k_vertex_color_unpack(kuint c) {
  return v4((float)(c & 0xFFu) / 255.0f, (float)((c >> 8) & 0xFFu) / 255.0f, (float)((c >> 16) & 0xFFu) / 255.0f,
            (float)((c >> 24) & 0xFFu) / 255.0f);
}

KFN KVec4 k_hit_vertex_color(const KSceneView* scene, kuint triangle, float u, float v, kuint material_flags) {
  if (!(material_flags & (K_MAT_VERTEX_COLOR | K_MAT_INVERSE_VERTEX_COLOR))) return v4(1.0f, 1.0f, 1.0f, 1.0f);
  KTriangle tri = scene->triangles[triangle];
  KVec4 a = k_vertex_color_unpack(scene->vertex_colors[tri.v0]);
  KVec4 b = k_vertex_color_unpack(scene->vertex_colors[tri.v1]);
  KVec4 c = k_vertex_color_unpack(scene->vertex_colors[tri.v2]);
  float w = 1.0f - u - v;
  KVec4 vc = v4(w * a.x + u * b.x + v * c.x, w * a.y + u * b.y + v * c.y, w * a.z + u * b.z + v * c.z,
                w * a.w + u * b.w + v * c.w);
  if (material_flags & K_MAT_INVERSE_VERTEX_COLOR) return v4(1.0f - vc.x, 1.0f - vc.y, 1.0f - vc.z, 1.0f);
  return vc;
}

/* Coverage of an alpha-tested surface at the hit: the diffuse map's alpha times the colour's. */
KFN float k_hit_alpha(const KSceneView* scene, kuint triangle, float u, float v, KGLOBAL const KMaterial* m) {
  float alpha = m->diffuse_color[3];
  if (m->diffuse_tex != K_NONE) {
    float s, t;
    k_hit_st(scene, triangle, u, v, m, &s, &t);
    alpha *= k_texture_sample(scene, m->diffuse_tex, s, t).w;
  }
  return alpha;
}

/* What kind of ray the material hooks see (their shadow_ray argument). */
#define K_CAMERA_OR_BOUNCE_RAY 0
#define K_SHADOW_RAY 1
#define K_SHADOW_RAY_FROM_NO_SELF_SHADOW 2   /* leaves a noSelfShadow surface */

/* The kind of an occlusion ray with this ray mask. */
KFN int k_shadow_ray_kind(kuint ray_mask) {
  return (ray_mask & K_RAY_FLAG_FROM_NO_SELF_SHADOW) ? K_SHADOW_RAY_FROM_NO_SELF_SHADOW : K_SHADOW_RAY;
}

/* The mask of a shadow ray leaving a surface with these material flags. Per light the engine draws
 * the shadows of ordinary casters, lights the noSelfShadow receivers, then adds the noSelfShadow
 * casters' shadows for everything else (RB_ARB2_DrawInteractions): noSelfShadow surfaces, of any
 * entity, never shadow each other but do shadow ordinary surfaces. */
KFN kuint k_shadow_ray_mask(kuint surface_flags) {
  return K_RAY_SHADOW | ((surface_flags & K_MAT_NO_SELF_SHADOW) ? K_RAY_FLAG_FROM_NO_SELF_SHADOW : 0u);
}

/* The hook both ways of tracing call for every candidate hit (Embree's filter functions and
 * bvh_traverse.h's K_SURFACE_TRANSMITTANCE): 1 when the ray passes through this surface, 0 when the
 * hit counts. Camera and bounce rays skip pass-through surfaces and alpha-test misses; shadow rays
 * also skip everything that is not an opaque shadow caster (translucent layers, noShadows decals) and,
 * leaving a noSelfShadow surface, other noSelfShadow surfaces. Sky surfaces block shadow rays (a sky
 * is not a light in Doom 3) unless their material is noShadows. shadow_ray: K_CAMERA_OR_BOUNCE_RAY,
 * K_SHADOW_RAY or K_SHADOW_RAY_FROM_NO_SELF_SHADOW. */
KFN float k_hit_transmittance(const KSceneView* scene, kuint instance, kuint triangle, float u, float v,
                              int shadow_ray) {
  KGLOBAL const KMaterial* m = &scene->materials[k_hit_material(scene, instance, triangle)];
  if (m->blend == K_BLEND_PASSTHROUGH) return 1.0f;
  if (shadow_ray) {
    if (m->blend != K_BLEND_OPAQUE && m->blend != K_BLEND_SKY) return 1.0f;
    if (m->flags & (K_MAT_NO_SHADOWS | K_MAT_TRANSLUCENT)) return 1.0f;
    if (shadow_ray == K_SHADOW_RAY_FROM_NO_SELF_SHADOW && (m->flags & K_MAT_NO_SELF_SHADOW)) return 1.0f;
  }
  if ((m->flags & K_MAT_ALPHA_TEST) && k_hit_alpha(scene, triangle, u, v, m) < m->alpha_ref) return 1.0f;
  return 0.0f;
}

/* Doom 3 has one specular map; we read its luminance as glossiness: bright, sharp highlights for
 * metal and polished surfaces, dull broad ones for stone and cloth. */
KFN void k_gloss_to_roughness_metallic(float gloss, float* roughness, float* metallic) {
  gloss = k_saturate(gloss);
  *roughness = 1.0f - 0.75f * k_sqrt(gloss);
  *metallic = k_saturate((gloss - 0.5f) * 2.0f);
}

KFN KVec3 k_vertex_normal(KGLOBAL const KVertex* a, KGLOBAL const KVertex* b, KGLOBAL const KVertex* c,
                          float u, float v) {
  float w = 1.0f - u - v;
  return v3(w * a->normal[0] + u * b->normal[0] + v * c->normal[0],
            w * a->normal[1] + u * b->normal[1] + v * c->normal[1],
            w * a->normal[2] + u * b->normal[2] + v * c->normal[2]);
}

/* cone_width: the width of the ray's footprint at the hit (world units, across the ray), which picks
 * the mip level: texture-space footprint = cone_width / |cos| * sqrt(uv area / world area). */
KFN KSurface k_surface_eval(const KSceneView* scene, KHit hit, KVec3 ray_org, KVec3 ray_dir, float cone_width) {
  KSurface sf;
  KGLOBAL const KInstance* inst = &scene->instances[hit.instance];
  KTriangle tri = scene->triangles[hit.triangle];
  kuint mat = k_hit_material(scene, hit.instance, hit.triangle);
  KGLOBAL const KMaterial* m = &scene->materials[mat];
  KGLOBAL const KVertex* a = &scene->vertices[tri.v0];
  KGLOBAL const KVertex* b = &scene->vertices[tri.v1];
  KGLOBAL const KVertex* c = &scene->vertices[tri.v2];
  float u = hit.u, v = hit.v, w = 1.0f - hit.u - hit.v;

  sf.position = v3_madd(ray_org, ray_dir, hit.t);
  KVec3 p0 = v3_load_g(a->pos), p1 = v3_load_g(b->pos), p2 = v3_load_g(c->pos);
  KVec3 ng = xform_normal_by_inverse_g(inst->world_to_object, v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
  ng = v3_normalize(ng);
  int flipped = v3_dot(ng, ray_dir) > 0.0f;
  if (flipped) ng = v3_neg(ng);
  sf.geo_normal = ng;

  KVec3 n_obj = k_vertex_normal(a, b, c, u, v);
  KVec3 n = v3_normalize(xform_normal_by_inverse_g(inst->world_to_object, n_obj));
  if (v3_dot(n_obj, n_obj) < 1e-12f) n = ng;
  if (v3_dot(n, ng) < 0.0f) n = v3_neg(n);

  float s, t;
  k_hit_st(scene, hit.triangle, u, v, m, &s, &t);

  /* Texture-space footprint from the triangle's uv density (after the material's transform). */
  float footprint = 0.0f;
  {
    float du1 = b->u - a->u, dv1 = b->v - a->v, du2 = c->u - a->u, dv2 = c->v - a->v;
    float det = m->tex_transform[0] * m->tex_transform[4] - m->tex_transform[1] * m->tex_transform[3];
    float uv_area = k_fabs((du1 * dv2 - dv1 * du2) * det);
    KVec3 ew = xform_vector_g(inst->object_to_world, v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
    float world_area = v3_length(ew);
    float cos_in = k_fmax(k_fabs(v3_dot(ng, ray_dir)), 0.1f);
    if (world_area > 0.0f) footprint = cone_width / cos_in * k_sqrt(uv_area / world_area);
  }

  if (m->normal_tex != K_NONE) {
    KVec3 tan_obj = v3(w * a->tangent[0] + u * b->tangent[0] + v * c->tangent[0],
                       w * a->tangent[1] + u * b->tangent[1] + v * c->tangent[1],
                       w * a->tangent[2] + u * b->tangent[2] + v * c->tangent[2]);
    KVec3 tn = xform_vector_g(inst->object_to_world, tan_obj);
    /* Gram-Schmidt against the shading normal; degenerate tangents fall back to an arbitrary basis. */
    tn = v3_sub(tn, v3_scale(n, v3_dot(tn, n)));
    KVec3 bt;
    if (v3_dot(tn, tn) < 1e-10f) {
      KFrame f = k_frame_from_normal(n);
      tn = f.t;
      bt = f.b;
    } else {
      tn = v3_normalize(tn);
      float sign = a->bitangent_sign < 0.0f ? -1.0f : 1.0f;
      bt = v3_scale(v3_cross(n, tn), sign);
    }
    KVec3 ln = k_texture_normal(scene, m->normal_tex, s, t, footprint);
    KVec3 pn = v3_normalize(v3_add(v3_add(v3_scale(tn, ln.x), v3_scale(bt, ln.y)), v3_scale(n, k_fmax(ln.z, 0.0f))));
    if (v3_dot(pn, ng) > 0.0f) n = pn;
  }
  sf.normal = n;

  /* The engine multiplies the whole interaction (diffuse and specular) and the ambient stages by it. */
  KVec4 vertex_color = k_hit_vertex_color(scene, hit.triangle, u, v, m->flags);
  /* A terrain blend's second diffuse stage takes what the first one's vertex colour leaves (its specular
   * is the material's, untinted). One texture read site for both stages: each inlined read costs the
   * GPU kernel registers and code. */
  KVec4 diffuse = v4(0.0f, 0.0f, 0.0f, 0.0f);
  KVec4 weight = vertex_color;
  kuint stages = m->blend_diffuse_tex1 != 0u ? 2u : 1u;
  for (kuint stage = 0u; stage < stages; ++stage) {
    KVec4 c = v4(m->diffuse_color[0], m->diffuse_color[1], m->diffuse_color[2], m->diffuse_color[3]);
    kuint tex = stage == 0u ? m->diffuse_tex : m->blend_diffuse_tex1 - 1u;
    if (tex != K_NONE) {
      KVec4 d = k_texture_sample_footprint(scene, tex, s, t, footprint);
      c = v4(c.x * d.x, c.y * d.y, c.z * d.z, c.w * d.w);
    }
    diffuse = v4(diffuse.x + c.x * weight.x, diffuse.y + c.y * weight.y, diffuse.z + c.z * weight.z,
                 stage == 0u ? c.w * weight.w : diffuse.w);
    weight = v4(1.0f - vertex_color.x, 1.0f - vertex_color.y, 1.0f - vertex_color.z, 0.0f);
  }
  if (stages == 2u) vertex_color = v4(1.0f, 1.0f, 1.0f, vertex_color.w);
  sf.albedo = v4_rgb(diffuse);
  sf.alpha = diffuse.w;

  KVec3 spec = v3(m->specular_color[0], m->specular_color[1], m->specular_color[2]);
  if (m->specular_tex != K_NONE) spec = v3_mul(spec, v4_rgb(k_texture_sample_footprint(scene, m->specular_tex, s, t, footprint)));
  if (m->flags & K_MAT_NO_SPECULAR) spec = v3s(0.0f);
  k_gloss_to_roughness_metallic(v3_luminance(spec), &sf.roughness, &sf.metallic);
  sf.specular = v3_mul(spec, v4_rgb(vertex_color));   /* after the gloss: the tint darkens, not roughens */
  sf.albedo = v3_scale(sf.albedo, 1.0f - sf.metallic);

  sf.emission = v3s(0.0f);
  if (m->flags & K_MAT_EMISSIVE) {
    KVec3 e = v3(m->emissive_color[0], m->emissive_color[1], m->emissive_color[2]);
    if (m->emissive_tex != K_NONE) e = v3_mul(e, v4_rgb(k_texture_sample_footprint(scene, m->emissive_tex, s, t, footprint)));
    sf.emission = v3_mul(e, v4_rgb(vertex_color));
  }
  sf.blend = m->blend;
  sf.flags = m->flags;
  sf.material = mat;
  return sf;
}

#endif
