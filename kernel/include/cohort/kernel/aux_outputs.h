/* Auxiliary outputs (a G-buffer) for temporal reprojection and denoising, written once for every tracer.
 * Include after integrator.h (it uses the same KTraceCtx and k_trace_closest).
 *
 * Per pixel, from one ray through the pixel's centre (not the jittered samples: the planes must be the
 * same on every tracer and free of noise), at the first opaque surface (transparent layers are crossed
 * as the path does):
 *   depth       distance along the camera's forward axis; 0 on a miss
 *   prev_depth  the same point's depth in the previous frame's camera (after its object's motion); the
 *               reprojection compares it with the history's depth to find disocclusions
 *   motion      screen offset, in pixels, from this pixel's centre to where the point was in the previous
 *               frame: previous position = (x + 0.5, y + 0.5) + motion. A miss moves with the camera's
 *               rotation only (a point at infinity). K_AUX_NO_MOTION when the point was behind the
 *               previous camera.
 *   normal      world-space shading normal (unit); 0 on a miss
 *   albedo      linear diffuse reflectance plus emission, clamped to [0, 1] (what OIDN wants); on a sky
 *               surface (treated as a miss otherwise) the sky's colour
 *   id          the instance's entity + 1 (0 for the world), K_NONE on a miss: stable across frames,
 *               unlike instance indices, which follow the TLAS leaf order
 * Object motion (KAuxHistory): object_to_world holds, per instance (the KInstance array's order), the
 * 3x4 row-major object-to-world transform of the previous frame (12 floats each); a null pointer means
 * no object moved. A skinned character's point (a hit on a BLAS some KSkin poses) was where the same
 * barycentrics of its triangle lay in the previous pose: its three corners skinned again with the
 * previous frame's joints (`joints`, the joint pool as it was; null: no skin moved). The host keeps both
 * (tracers/common's TracerBase, from the scene copy before each commit). */
#ifndef COHORT_KERNEL_AUX_OUTPUTS_H
#define COHORT_KERNEL_AUX_OUTPUTS_H
#include "aux_history.h"
#include "integrator.h"

/* Where a hit's point was in the previous frame, in the instance's object space. */
KFN KVec3 k_aux_previous_object_point(const KSceneView* scene, const KAuxHistory* history, KHit hit, KVec3 p_world) {
  KGLOBAL const KInstance* inst = &scene->instances[hit.instance];
  if (history->joints) {
    for (kuint s = 0u; s < history->skin_count; ++s) {
      KSkin skin = history->skins[s];
      if (skin.blas != inst->blas) continue;
      KTriangle tri = scene->triangles[hit.triangle];
      kuint i0 = tri.v0 - skin.vertex_offset, i1 = tri.v1 - skin.vertex_offset, i2 = tri.v2 - skin.vertex_offset;
      if (i0 >= skin.vertex_count || i1 >= skin.vertex_count || i2 >= skin.vertex_count) break;
      KVec3 p0 = k_skinned_point(history->skin_vertices, history->skin_weights, history->joints, skin, i0);
      KVec3 p1 = k_skinned_point(history->skin_vertices, history->skin_weights, history->joints, skin, i1);
      KVec3 p2 = k_skinned_point(history->skin_vertices, history->skin_weights, history->joints, skin, i2);
      return v3_add(v3_add(v3_scale(p0, 1.0f - hit.u - hit.v), v3_scale(p1, hit.u)), v3_scale(p2, hit.v));
    }
  }
  return xform_point_g(inst->world_to_object, p_world);
}


/* Where a world point lands on the camera's image, in pixels (y down), and its depth; 0 when it lies
 * behind the camera. */
KFN int k_project_point(const KCamera* cam, KVec3 p, float* px, float* py, float* depth) {
  KVec3 d = v3_sub(p, v3_load(cam->origin));
  float z = v3_dot(d, v3_load(cam->forward));
  *depth = z;
  if (!(z > 1e-6f)) return 0;
  float sx = v3_dot(d, v3_load(cam->right)) / (z * cam->tan_half_fov_x);
  float sy = v3_dot(d, v3_load(cam->up)) / (z * cam->tan_half_fov_y);
  *px = (sx + 1.0f) * 0.5f * (float)cam->width;
  *py = (1.0f - sy) * 0.5f * (float)cam->height;
  return 1;
}

/* A direction (a point at infinity) on the camera's image. */
KFN int k_project_direction(const KCamera* cam, KVec3 dir, float* px, float* py) {
  float z = v3_dot(dir, v3_load(cam->forward));
  if (!(z > 1e-6f)) return 0;
  float sx = v3_dot(dir, v3_load(cam->right)) / (z * cam->tan_half_fov_x);
  float sy = v3_dot(dir, v3_load(cam->up)) / (z * cam->tan_half_fov_y);
  *px = (sx + 1.0f) * 0.5f * (float)cam->width;
  *py = (1.0f - sy) * 0.5f * (float)cam->height;
  return 1;
}

KFN void k_pixel_aux(KTraceCtx* ctx, const KCamera* cam, const KCamera* prev_cam, const KAuxHistory* history, kuint x,
                     kuint y, KAux* out) {
  const KSceneView* scene = K_CTX_SCENE(ctx);
  float cx = (float)x + 0.5f, cy = (float)y + 0.5f;
  KVec3 org = v3_load(cam->origin);
  KVec3 dir = k_camera_direction(cam, cx, cy);
  float pixel_spread = 2.0f * cam->tan_half_fov_x / (float)cam->width;
  out->depth = 0.0f;
  out->prev_depth = 0.0f;
  out->motion[0] = K_AUX_NO_MOTION;
  out->motion[1] = K_AUX_NO_MOTION;
  out->normal[0] = out->normal[1] = out->normal[2] = 0.0f;
  out->albedo[0] = out->albedo[1] = out->albedo[2] = 0.0f;
  out->id = K_NONE;
  out->pad = 0u;
  KVec3 ray_org = org;
  for (kuint layer = 0u; layer <= K_MAX_LAYERS; ++layer) {
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(ctx, ray_org, dir, K_INF, K_RAY_PRIMARY, &hit)) break;
    KSurface sf = k_surface_eval(scene, hit, ray_org, dir, pixel_spread * hit.t);
    if (sf.blend == K_BLEND_SKY) {
      /* Infinitely far, as a miss (depth 0, motion by the camera's rotation), but with its colour. */
      KVec3 sky = k_sky_radiance(scene, hit.instance, sf.material, dir);
      out->albedo[0] = k_saturate(sky.x);
      out->albedo[1] = k_saturate(sky.y);
      out->albedo[2] = k_saturate(sky.z);
      break;
    }
    if (sf.blend != K_BLEND_OPAQUE) {
      ray_org = v3_madd(sf.position, dir, k_ray_epsilon(sf.position));
      continue;
    }
    KGLOBAL const KInstance* inst = &scene->instances[hit.instance];
    KVec3 p = sf.position;
    KVec3 p_prev = p;
    if (history->object_to_world || history->joints) {
      KVec3 p_object = k_aux_previous_object_point(scene, history, hit, p);
      p_prev = history->object_to_world ? xform_point_g(history->object_to_world + 12u * hit.instance, p_object)
                                        : xform_point_g(inst->object_to_world, p_object);
    }
    out->depth = v3_dot(v3_sub(p, org), v3_load(cam->forward));
    out->normal[0] = sf.normal.x;
    out->normal[1] = sf.normal.y;
    out->normal[2] = sf.normal.z;
    KVec3 a = v3_add(sf.albedo, sf.emission);
    out->albedo[0] = k_saturate(a.x);
    out->albedo[1] = k_saturate(a.y);
    out->albedo[2] = k_saturate(a.z);
    out->id = inst->entity + 1u;
    float px, py, pz;
    if (k_project_point(prev_cam, p_prev, &px, &py, &pz)) {
      out->motion[0] = px - cx;
      out->motion[1] = py - cy;
    }
    out->prev_depth = pz;
    return;
  }
  float px, py;
  if (k_project_direction(prev_cam, dir, &px, &py)) {
    out->motion[0] = px - cx;
    out->motion[1] = py - cy;
  }
}

#endif
