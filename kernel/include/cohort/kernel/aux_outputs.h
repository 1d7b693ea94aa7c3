/* Auxiliary outputs (a G-buffer) for temporal reprojection and denoising, written once for every tracer.
 * Include after integrator.h (it uses the same KTraceCtx and k_trace_closest).
 *
 * Per pixel, at the first opaque surface (transparent layers are crossed as the path does), from one of
 * two rays (KFrameParams.aux_outputs, aux_mode.h):
 *   K_AUX_CENTRE_RAY      a ray of its own through the pixel's centre (k_pixel_aux): steady planes, but
 *                         a second trace of every first hit;
 *   K_AUX_PATH_FIRST_HIT  the first sample's own camera ray: its path records which triangle it met
 *                         (k_trace_path's first_hit) and k_aux_from_first_hit finishes the planes from
 *                         it without tracing; positions (motion's origin) are the sample's, jittered.
 * Either way every tracer writes the same planes for the same frame. The planes:
 *   depth       distance along the camera's forward axis; 0 on a miss
 *   prev_depth  the same point's depth in the previous frame's camera (after its object's motion); the
 *               reprojection compares it with the history's depth to find disocclusions
 *   motion      screen offset, in pixels, from where the ray left the image (the pixel's centre, or the
 *               sample's position) to where the point was in the previous frame: previous position =
 *               (x + 0.5, y + 0.5) + motion for centre rays. A miss moves with the camera's
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
#include "aux_mode.h"
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

/* Depth, previous depth and motion of the surface point p of a hit, seen at image position (sx, sy). */
KFN void k_aux_surface_motion(const KSceneView* scene, const KCamera* cam, const KCamera* prev_cam,
                              const KAuxHistory* history, KHit hit, KVec3 p, float sx, float sy, KAux* out) {
  KGLOBAL const KInstance* inst = &scene->instances[hit.instance];
  KVec3 p_prev = p;
  if (history->object_to_world || history->joints) {
    KVec3 p_object = k_aux_previous_object_point(scene, history, hit, p);
    p_prev = history->object_to_world ? xform_point_g(history->object_to_world + 12u * hit.instance, p_object)
                                      : xform_point_g(inst->object_to_world, p_object);
  }
  out->depth = v3_dot(v3_sub(p, v3_load(cam->origin)), v3_load(cam->forward));
  float px, py, pz;
  if (k_project_point(prev_cam, p_prev, &px, &py, &pz)) {
    out->motion[0] = px - sx;
    out->motion[1] = py - sy;
  }
  out->prev_depth = pz;
}

/* Motion of a miss seen along dir at image position (sx, sy): the camera's rotation only. */
KFN void k_aux_miss_motion(const KCamera* prev_cam, KVec3 dir, float sx, float sy, KAux* out) {
  float px, py;
  if (k_project_direction(prev_cam, dir, &px, &py)) {
    out->motion[0] = px - sx;
    out->motion[1] = py - sy;
  }
}

/* The planes of an opaque surface sf (of hit) seen at image position (sx, sy). */
KFN void k_aux_surface(const KSceneView* scene, const KCamera* cam, const KCamera* prev_cam,
                       const KAuxHistory* history, KHit hit, const KSurface* sf, float sx, float sy, KAux* out) {
  out->normal[0] = sf->normal.x;
  out->normal[1] = sf->normal.y;
  out->normal[2] = sf->normal.z;
  KVec3 a = v3_add(sf->albedo, sf->emission);
  out->albedo[0] = k_saturate(a.x);
  out->albedo[1] = k_saturate(a.y);
  out->albedo[2] = k_saturate(a.z);
  out->id = scene->instances[hit.instance].entity + 1u;
  k_aux_surface_motion(scene, cam, prev_cam, history, hit, sf->position, sx, sy, out);
}

/* A sky surface: infinitely far, as a miss (depth 0, motion by the camera's rotation), with its colour. */
KFN void k_aux_sky(const KCamera* prev_cam, KVec3 dir, KVec3 sky, float sx, float sy, KAux* out) {
  out->albedo[0] = k_saturate(sky.x);
  out->albedo[1] = k_saturate(sky.y);
  out->albedo[2] = k_saturate(sky.z);
  k_aux_miss_motion(prev_cam, dir, sx, sy, out);
}

KFN void k_aux_clear(KAux* out) {
  out->depth = 0.0f;
  out->prev_depth = 0.0f;
  out->motion[0] = K_AUX_NO_MOTION;
  out->motion[1] = K_AUX_NO_MOTION;
  out->normal[0] = out->normal[1] = out->normal[2] = 0.0f;
  out->albedo[0] = out->albedo[1] = out->albedo[2] = 0.0f;
  out->id = K_NONE;
  out->pad = 0u;
}

/* K_AUX_CENTRE_RAY: the aux planes of pixel (x, y) from a ray of its own through the pixel's centre. */
KFN void k_pixel_aux(KTraceCtx* ctx, const KCamera* cam, const KCamera* prev_cam, const KAuxHistory* history, kuint x,
                     kuint y, KAux* out) {
  const KSceneView* scene = K_CTX_SCENE(ctx);
  float cx = (float)x + 0.5f, cy = (float)y + 0.5f;
  KVec3 org = v3_load(cam->origin);
  KVec3 dir = k_camera_direction(cam, cx, cy);
  float pixel_spread = 2.0f * cam->tan_half_fov_x / (float)cam->width;
  k_aux_clear(out);
  KVec3 ray_org = org;
  for (kuint layer = 0u; layer <= K_MAX_LAYERS; ++layer) {
    KHit hit;
    hit.cost = 0u;
    if (!k_trace_closest(ctx, ray_org, dir, K_INF, K_RAY_PRIMARY, &hit)) break;
    KSurface sf = k_surface_eval(scene, hit, ray_org, dir, pixel_spread * hit.t);
    if (sf.blend == K_BLEND_SKY) {
      k_aux_sky(prev_cam, dir, k_sky_radiance(scene, hit.instance, sf.material, dir), cx, cy, out);
      return;
    }
    if (sf.blend != K_BLEND_OPAQUE) {
      ray_org = v3_madd(sf.position, dir, k_ray_epsilon(sf.position));
      continue;
    }
    k_aux_surface(scene, cam, prev_cam, history, hit, &sf, cx, cy, out);
    return;
  }
  k_aux_miss_motion(prev_cam, dir, cx, cy, out);
}

/* K_AUX_PATH_FIRST_HIT: the aux planes of pixel (x, y) from what its first sample's path recorded
 * (k_trace_path's first_hit: which triangle). The sample's camera ray again (k_camera_sample's jitter, so
 * the same direction bit for bit), its point on the recorded triangle, the surface there, and depth and
 * motion as the centre ray works them out but at the sample's position in the pixel: a still camera gives
 * motion 0, and the history is fetched where the surface was. No ray is traced. */
KFN void k_aux_from_first_hit(const KSceneView* scene, const KFrameParams* params, const KCamera* cam,
                              const KCamera* prev_cam, const KAuxHistory* history, kuint x, kuint y,
                              KPathFirstHit record, KAux* out) {
  KRng rng;
  float sx, sy;
  k_camera_sample_position(params, x, y, 0u, &rng, &sx, &sy);
  KVec3 dir = k_camera_direction(cam, sx, sy);
  k_aux_clear(out);
  if (record.instance == K_NONE) {
    k_aux_miss_motion(prev_cam, dir, sx, sy, out);
    return;
  }
  if (record.sky) {
    KVec3 sky = k_sky_radiance(scene, record.instance, k_hit_material(scene, record.instance, record.triangle), dir);
    k_aux_sky(prev_cam, dir, sky, sx, sy, out);
    return;
  }
  /* The ray in the instance's object space, as the walk intersected it, against the triangle's plane (no
   * edge tests: the path found this triangle, rounding must not lose it). */
  KGLOBAL const KInstance* inst = &scene->instances[record.instance];
  KVec3 org = v3_load(cam->origin);
  KVec3 o = xform_point_g(inst->world_to_object, org), d = xform_vector_g(inst->world_to_object, dir);
  KTriangle tri = scene->triangles[record.triangle];
  KVec3 p0 = v3_load_g(scene->vertices[tri.v0].pos);
  KVec3 e1 = v3_sub(v3_load_g(scene->vertices[tri.v1].pos), p0), e2 = v3_sub(v3_load_g(scene->vertices[tri.v2].pos), p0);
  KVec3 pv = v3_cross(d, e2);
  float det = v3_dot(e1, pv);
  KHit hit;
  hit.instance = record.instance;
  hit.triangle = record.triangle;
  hit.cost = 0u;
  hit.t = 0.0f;
  hit.u = hit.v = 0.0f;
  if (k_fabs(det) > 1e-30f) {
    float inv_det = 1.0f / det;
    KVec3 s = v3_sub(o, p0), q = v3_cross(s, e1);
    hit.t = v3_dot(e2, q) * inv_det;
    hit.u = v3_dot(s, pv) * inv_det;
    hit.v = v3_dot(d, q) * inv_det;
  }
  if (!(hit.t > 0.0f)) {
    k_aux_miss_motion(prev_cam, dir, sx, sy, out);
    return;
  }
  KSurface sf = k_surface_eval(scene, hit, org, dir, k_pixel_spread(cam) * hit.t);
  k_aux_surface(scene, cam, prev_cam, history, hit, &sf, sx, sy, out);
}

#endif
