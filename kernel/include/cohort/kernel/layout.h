/* GPU data layouts: every struct a tracer reads, identical in C++, CUDA and OpenCL C. Only 4-byte
 * scalars and arrays of them, sizes multiples of 16 bytes, so no compiler inserts padding.
 * Indices are kuint; "none" is K_NONE. */
#ifndef COHORT_KERNEL_LAYOUT_H
#define COHORT_KERNEL_LAYOUT_H
#include "portable.h"

#define K_NONE 0xFFFFFFFFu

/* ---- BVH (shared by BLAS and TLAS) ------------------------------------------------------------
 * count == 0: interior node, children at left_first and left_first + 1.
 * count  > 0: leaf over primitives [left_first, left_first + count).
 * In a BLAS, child indices are relative to KBlas.node_offset and primitive indices to
 * KBlas.tri_offset, so a BLAS built once can be uploaded anywhere. In the TLAS, primitives are
 * instances (KInstance array order is TLAS leaf order). */
typedef struct KBvhNode {
  float bmin[3]; kuint left_first;
  float bmax[3]; kuint count;
} KBvhNode;

/* Builders never produce a tree deeper than this many levels, so a traversal stack of this many
 * entries (near-child-first, one push per level) cannot overflow. */
#define K_BVH_MAX_DEPTH 48

/* A triangle ready for Moller-Trumbore with no vertex indices to follow: its first corner and the edges
 * to the other two (e1 = p1 - p0, e2 = p2 - p0), object space, parallel to the triangle array (same
 * index). A GPU tracer keeps it beside the triangles so a leaf's test is three adjacent 16-byte loads
 * instead of a triangle load and then three vertex loads that wait on it. */
typedef struct KTriangleEdges {
  float p0[3]; float pad0;
  float e1[3]; float pad1;
  float e2[3]; float pad2;
} KTriangleEdges;

typedef struct KBlas {
  kuint node_offset; kuint node_count;
  kuint tri_offset;  kuint tri_count;
} KBlas;

/* Instance mask bits: a ray carries a mask and skips instances that share no bit with it. */
#define K_MASK_PRIMARY 1u   /* visible to camera and bounce rays */
#define K_MASK_SHADOW  2u   /* casts shadows (cleared for noShadows entities) */
/* Not an instance bit (no instance carries it): a shadow ray carries it when it leaves a noSelfShadow
 * surface, so that the material hooks let other noSelfShadow surfaces through (k_shadow_ray_kind). */
#define K_RAY_FLAG_FROM_NO_SELF_SHADOW 4u

typedef struct KInstance {
  float object_to_world[12];  /* 3x4 row-major */
  float world_to_object[12];
  kuint blas;                 /* index into the KBlas array */
  kuint mask;
  kuint entity;               /* the idRenderWorld handle, for picking; K_NONE for the world */
  kuint material_override;    /* K_NONE: use the triangles' own materials */
} KInstance;

/* ---- Geometry ---------------------------------------------------------------------------------- */
typedef struct KVertex {
  float pos[3];     float u;
  float normal[3];  float v;
  float tangent[3]; float bitangent_sign;  /* bitangent = sign * cross(normal, tangent) */
} KVertex;

/* Vertex colours: one kuint per vertex, parallel to the vertex array (same index), RGBA8 with R in the
 * low byte, as the engine's idDrawVert::color bytes. A separate array keeps KVertex at 48 bytes; meshes
 * whose format has no colours carry white (0xFFFFFFFF). */
typedef kuint KVertexColor;
#define K_VERTEX_COLOR_WHITE 0xFFFFFFFFu

/* Vertex indices are absolute into the vertex array; winding as stored in the .proc. */
typedef struct KTriangle {
  kuint v0, v1, v2;
  kuint material;
} KTriangle;

/* ---- Materials ----------------------------------------------------------------------------- */
/* How a hit is treated (Doom 3 path tracer write-up, "blend-mode classification"). */
#define K_BLEND_OPAQUE      0u  /* lit surface: the path bounces here */
#define K_BLEND_PASSTHROUGH 1u  /* invisible to rays (nodraw, editor, fog/blend lights) */
#define K_BLEND_ADDITIVE    2u  /* adds its colour and lets the ray continue (glows, decals that add) */
#define K_BLEND_MODULATE    3u  /* multiplies throughput and continues (filter decals, tinted glass) */
#define K_BLEND_ALPHA       4u  /* mixes by alpha and continues (blend stages) */
#define K_BLEND_SKY         5u  /* a cube map read by the ray's direction (sky.h); the path ends there. It
                                 * blocks shadow rays unless K_MAT_NO_SHADOWS. emissive_tex: face +X, the
                                 * other faces follow in the texture table (-X, +Y, -Y, +Z, -Z);
                                 * emissive_color: the stage colour; tex_transform[0..2] and [3..5]: the
                                 * axes X' and Y' (Z' = X' x Y') the model-space direction is read against */

#define K_MAT_ALPHA_TEST   1u
#define K_MAT_TRANSLUCENT  2u
#define K_MAT_NO_SHADOWS   4u
#define K_MAT_TWO_SIDED    8u
#define K_MAT_NONSOLID     16u
#define K_MAT_EMISSIVE     32u  /* ambient-only stages: an emitter */
#define K_MAT_VERTEX_COLOR 64u  /* vertexColor: the surface's colours x the vertex colour (RGBA) */
#define K_MAT_NO_SPECULAR  128u
#define K_MAT_NO_SELF_SHADOW 256u  /* noSelfShadow: does not shadow other noSelfShadow surfaces */
#define K_MAT_INVERSE_VERTEX_COLOR 512u  /* inverseVertexColor: colours x (1 - vertex RGB), alpha kept */
#define K_MAT_ENV_BY_NORMAL 1024u  /* the environment stage is `texgen normal`: cube by the model-space
                                    * vertex normal, not by the reflected view */
#define K_MAT_ENV_UNDER_LAYER 2048u  /* the environment stage comes before the layer's filter / blend stage,
                                      * which then filters the reflection too */

typedef struct KMaterial {
  float diffuse_color[4];   /* multiplies the diffuse map; rgba */
  float specular_color[4];
  float emissive_color[4];  /* multiplies the emissive map for K_MAT_EMISSIVE */
  float tex_transform[8];   /* st' = (m0 s + m1 t + m2, m3 s + m4 t + m5); m6, m7 unused */
  kuint diffuse_tex, normal_tex, specular_tex, emissive_tex;  /* K_NONE when absent */
  kuint flags;
  kuint blend;              /* K_BLEND_* */
  float alpha_ref;          /* alphaTest threshold */
  kuint blend_diffuse_tex1; /* terrain blends: 1 + the texture shown where the vertex colour leaves room
                               (x (1 - vertex RGB) where diffuse_tex is x vertex RGB, and the other way
                               round); 0: none, so zeroed materials and earlier packs have none */
  /* An environment cube-map stage (`texgen reflect`, or `texgen normal` with K_MAT_ENV_BY_NORMAL): at a
   * camera or bounce hit it adds env_color x the cube along the view reflected about the shading normal
   * (or along the vertex normal); environment.h. env_tex1: 1 + the texture of face +X, the other five
   * follow in the texture table as a sky's do; 0: no such stage, so zeroed materials have none. */
  float env_color[3];
  kuint env_tex1;
} KMaterial;

/* ---- Textures: RGBA8 texels (R in the low byte) in one buffer, mip levels stored one after another. */
#define K_TEX_CLAMP   1u
#define K_TEX_SRGB    2u    /* colour data: decode to linear on read */
#define K_TEX_NORMAL  4u    /* tangent-space normal map, X in R */

typedef struct KTexture {
  kuint offset;             /* first texel of level 0 in the texel buffer */
  kuint width, height;
  kuint flags_and_levels;   /* low 8 bits: K_TEX_* flags, bits 8..15: mip level count */
} KTexture;

/* ---- Lights ------------------------------------------------------------------------------------ */
#define K_LIGHT_POINT     0u
#define K_LIGHT_PARALLEL  1u
#define K_LIGHT_PROJECTED 2u

#define K_LIGHT_NO_SHADOWS  1u
#define K_LIGHT_NO_SPECULAR 2u
/* Light kinds of the light material (doom3-content.md section 9). Fog and blend lights light nothing:
 * next-event estimation skips them and the integrator applies them along rays (fog.h). Ambient lights
 * come with K_LIGHT_NO_SHADOWS | K_LIGHT_NO_SPECULAR and light from a constant tangent-space vector. */
#define K_LIGHT_FOG         4u
#define K_LIGHT_BLEND       8u
#define K_LIGHT_AMBIENT     16u
#define K_LIGHT_BLEND_ADD   32u   /* blend light whose stage is `blend add` (else it multiplies) */
#define K_LIGHT_VOLUME_EFFECT (K_LIGHT_FOG | K_LIGHT_BLEND)

typedef struct KLight {
  float origin[3];  kuint type;
  float color[3];   kuint flags;        /* colour already includes r_lightScale and the stage colour */
  float radius[3];  kuint light_tex;    /* light image sampled at (S/Q, T/Q); K_NONE: white */
  float center[3];  kuint falloff_tex;  /* falloff image at (F, 0.5); K_NONE: windowed (1-(d/r)^2)^2 */
  float axis[12];                       /* rows of the light axis, each padded to 4 floats */
  float plane_s[4]; float plane_t[4]; float plane_q[4]; float plane_f[4];  /* world space lightProject */
  float extent;                         /* soft-shadow jitter radius in world units */
  float fog_distance;                   /* fog lights: distance D of the engine's fog table */
  float volume_reach;                   /* box lights: farthest corner of the volume from origin; 0: unknown */
  float pad;
} KLight;

/* ---- Light trees: which light sources to sample at a point, at a cost that does not grow with their
 * number. The node array holds two binary trees, built by the core (core/light_sampling.h):
 *   - from node 0, the tree over the Doom 3 lights' world-space boxes (the finite volume outside which a
 *     light is zero); a leaf (count == 1) holds light left_first;
 *   - in the last 2E - 1 nodes (E = the emissive triangle count), root first, the tree over the emissive
 *     triangles' boxes; a leaf holds emissive triangle left_first (an index into KEmissiveTriangle).
 * count == 0: interior node, children at left_first and left_first + 1 (absolute indices). power: the
 * summed power of the sources below (light colour luminance; emissive area x power density);
 * light_count: how many; parent: the parent node, K_NONE at a root; reach: the largest half-extent (any
 * axis) of a source's box below, the size of a light in light_tree.h's k_light_node_guess (set in both
 * trees, read in the Doom 3 lights' only). */
typedef struct KLightNode {
  float bmin[3]; kuint left_first;
  float bmax[3]; kuint count;
  float power;   kuint light_count; kuint parent; float reach;
} KLightNode;

/* ---- Emissive triangles: every triangle whose material emits, in world space, sorted by (instance,
 * triangle) so that a hit finds its entry by binary search; leaf: its leaf in the emissive tree. */
typedef struct KEmissiveTriangle {
  float p0[3]; kuint instance;   /* p0..p2: world positions of the triangle's v0, v1, v2 */
  float p1[3]; kuint triangle;   /* absolute index into the triangle array */
  float p2[3]; kuint leaf;
} KEmissiveTriangle;

/* ---- Camera and per-frame parameters ------------------------------------------------------------- */
typedef struct KCamera {
  float origin[3];  float tan_half_fov_x;
  float forward[3]; float tan_half_fov_y;
  float right[3];   kuint width;
  float up[3];      kuint height;
} KCamera;

/* Debug views, like the seed renderer's r_cuMode. */
#define K_MODE_PATH     0u
#define K_MODE_DIRECT   1u   /* Whitted-style direct lighting only */
#define K_MODE_ALBEDO   2u
#define K_MODE_NORMALS  3u
#define K_MODE_SPECULAR 4u
#define K_MODE_BVH      5u   /* BVH traversal cost heat map */
#define K_MODE_TRIANGLES 6u  /* a colour per triangle */
#define K_MODE_COUNT    7u   /* how many modes: they run from 0 to K_MODE_COUNT - 1 */

/* How next-event estimation picks Doom 3 lights (KFrameParams.light_sampling). light_samples == 0
 * means K_LIGHTS_EVERY whatever this says. */
#define K_LIGHTS_TREE  0u   /* the light tree: only lights whose volume holds the point */
#define K_LIGHTS_ALL   1u   /* reference: a pick by contribution over every light of the map */
#define K_LIGHTS_EVERY 2u   /* reference: every light, one shadow ray each */
#define K_LIGHTS_GATHER 3u  /* `every` among the lights whose volume holds the point, at most about
                               light_samples shadow rays (integrator.h, light_gather.h) */
#define K_LIGHTS_IN_RANGE 4u  /* per light sample, one light picked by its unshadowed contribution among
                                 every light whose volume holds the point: the tree walked without its
                                 descent (light_tree.h); what the default, K_LIGHTS_AUTO, is on Doom 3 maps */
#define K_LIGHTS_DENSE 5u     /* for rooms where many lights reach a point: a descent of the tree by a guess
                                 of each subtree's contribution to at most K_LIGHT_DENSE_LEAF lights, then
                                 in-range within them (light_tree.h); a kernel build of its own on CUDA */
#define K_LIGHTS_AUTO 6u      /* the default (core::default_frame_params): in-range or dense, chosen per frame
                                 from the lights' density (core::resolve_light_sampling); the tracers resolve
                                 it before a kernel sees it */

/* light_count, instance_count, tlas_node_count, light_node_count and emissive_count are the lengths of
 * the scene's arrays, set by the host from the tracer's scene copy and read only by k_scene_view
 * (scene_view.h). emissive_samples: emissive triangles sampled per hit (0: emitters are found only by
 * bounce rays; 1: one sample, combined with the bounce by MIS). aux_outputs: 1 = the tracer also writes
 * the band's auxiliary planes (aux_outputs.h: depth, normal, albedo, id, motion), 0 = it does not (no cost).
 * [volume_light_begin, volume_light_end): the index range holding every fog and blend light
 * (K_LIGHT_VOLUME_EFFECT), empty when the map has none: rays and hits test only those lights' volumes,
 * not every light of a map with thousands. path_pixels, path_phase: sparse paths for dynamic resolution
 * (path_pattern.h: which pixels trace paths; 0 = every pixel; the aux planes cover every pixel anyway). */
typedef struct KFrameParams {
  kuint frame_index;  kuint spp;          kuint max_bounces;   kuint light_samples;
  float firefly_clamp; float spec_boost;  kuint mode;          kuint light_count;
  kuint row_begin;    kuint row_end;      kuint instance_count; kuint tlas_node_count;
  float soft_shadow_scale; float rr_start; kuint light_sampling; kuint light_node_count;
  kuint emissive_count; kuint emissive_samples; kuint aux_outputs; kuint volume_light_begin;
  kuint volume_light_end; float shadow_rr;  kuint path_pixels; kuint path_phase;
} KFrameParams;

/* One pixel's auxiliary outputs (aux_outputs.h says what each field means). */
#define K_AUX_NO_MOTION 1.0e9f   /* motion of a point that was behind the previous camera */
typedef struct KAux {
  float depth;     float prev_depth; float motion[2];
  float normal[3]; float albedo[3];  kuint id;       kuint pad;
} KAux;

/* KFrameParams.aux_outputs: 0 = none; K_AUX_CENTRE_RAY = from one unjittered ray through each pixel's centre
 * (a pass of its own); K_AUX_PATH_FIRST_HIT = from the first sample's camera ray, recorded by the path as it
 * goes (KPathFirstHit) and finished afterwards (aux_outputs.h): no ray of its own, the planes jittered as
 * the samples are. Tracers take the centre ray where paths do not cover every pixel (sparse paths). */
#define K_AUX_CENTRE_RAY     1u
#define K_AUX_PATH_FIRST_HIT 2u

/* What a path records of its first opaque surface for the aux planes (K_AUX_PATH_FIRST_HIT): only which
 * triangle it is (instance K_NONE: a miss; sky 1: the sky's surface), so that the megakernel keeps no more
 * values live than before; the planes are worked out from it afterwards (aux_outputs.h). */
typedef struct KPathFirstHit {
  kuint instance; kuint triangle; kuint sky; kuint pad;
} KPathFirstHit;

/* KAux as it travels to the host (core's BandBuffer): 32 bytes, the normal and albedo as IEEE half
 * floats (their bits). GPU tracers pack it on the device so that only these bytes cross the bus. */
typedef struct KAuxTexel {
  float depth; float prev_depth; float motion[2];
  unsigned short normal[3]; unsigned short albedo[3]; kuint id;
} KAuxTexel;

#if defined(__cplusplus) && !defined(__CUDACC_RTC__)
static_assert(sizeof(KAux) == 48, "KAux layout");
static_assert(sizeof(KAuxTexel) == 32, "KAuxTexel layout");
static_assert(sizeof(KPathFirstHit) == 16, "KPathFirstHit layout");
static_assert(sizeof(KBvhNode) == 32, "KBvhNode layout");
static_assert(sizeof(KBlas) == 16, "KBlas layout");
static_assert(sizeof(KTriangleEdges) == 48, "KTriangleEdges layout");
static_assert(sizeof(KInstance) == 112, "KInstance layout");
static_assert(sizeof(KVertex) == 48, "KVertex layout");
static_assert(sizeof(KVertexColor) == 4, "KVertexColor layout");
static_assert(sizeof(KTriangle) == 16, "KTriangle layout");
static_assert(sizeof(KMaterial) == 128, "KMaterial layout");
static_assert(sizeof(KTexture) == 16, "KTexture layout");
static_assert(sizeof(KLight) == 192, "KLight layout");
static_assert(sizeof(KCamera) == 64, "KCamera layout");
static_assert(sizeof(KLightNode) == 48, "KLightNode layout");
static_assert(sizeof(KEmissiveTriangle) == 48, "KEmissiveTriangle layout");
static_assert(sizeof(KFrameParams) == 96, "KFrameParams layout");
#endif

#endif
