// The in-memory scene model: what Cohort knows about a Doom 3 level, independent of the files it
// came from. Loaders fill it from .proc/.map/.mtr and images; scene deltas (render_world.h) change it.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace cohort::scene {

// Decoded texture, RGBA8, rows top to bottom as the image file stores them.
struct Image {
  std::string name;        // as a material names it, without extension ("textures/base/floor1")
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  bool is_normal_map = false;  // tangent-space normal map, X in R (file order, not the engine's RXGB upload)
  bool is_placeholder = false; // generated because the file was missing or unreadable
};

// Sky: an unlit surface whose stage is a cube map looked up by the ray direction (`texgen skybox` or
// `wobbleSky`, doom3-content.md section 8); rays that reach it see the cube and end there.
enum class BlendClass : uint8_t { Opaque, PassThrough, Additive, Modulate, Alpha, Sky };

struct MaterialRegisters;

// What a light material makes of its light (Material.h fogLight / blendLight / ambientLight).
enum class LightKind : uint8_t { Normal, Fog, Blend, Ambient };

struct Material {
  std::string name;
  std::string source_file; int source_line = 0;
  int diffuse_image = -1, normal_image = -1, specular_image = -1, emissive_image = -1;  // into Scene::images
  glm::vec4 diffuse_color{1.0f}, specular_color{1.0f}, emissive_color{0.0f};
  float tex_transform[6] = {1, 0, 0, 0, 1, 0};  // st' = (m0 s + m1 t + m2, m3 s + m4 t + m5)
  bool alpha_test = false; float alpha_ref = 0.5f;
  bool translucent = false, no_shadows = false, two_sided = false, nonsolid = false;
  bool emitter = false;        // ambient-only stages: emits its stage image
  bool vertex_color = false;         // a stage is `vertexColor`: colours x the vertex colour
  bool inverse_vertex_color = false; // a stage is `inverseVertexColor`: colours x (1 - vertex RGB)
  // A second diffuse stage in the other vertex colour mode (terrain blends: one stage `vertexColor`, the
  // next `inverseVertexColor`): shown where the first one's vertex colour leaves room. Its colour is the
  // first stage's (one diffuse colour per material here).
  int blend_diffuse_image = -1;
  bool no_self_shadow = false; // noSelfShadow: never shadows, nor is shadowed by, other noSelfShadow surfaces
  BlendClass blend = BlendClass::Opaque;
  // Sky: six consecutive Scene::images, the cube faces +X, -X, +Y, -Y, +Z, -Z (GL order), and the
  // axes the model-space ray direction is read against (identity for skybox, wobbleSky's rotation).
  int sky_cube_image = -1;
  glm::mat3 sky_axis{1.0f};
  // Environment stage (`cubeMap` / `cameraCubeMap` with `texgen reflect` or `texgen normal`, `blend add`):
  // glass and chrome. Six consecutive Scene::images like the sky's (-1: none); camera and bounce rays
  // that hit the surface see environment_color x the cube along the view reflected about the surface
  // normal, or along the vertex normal when environment_by_normal (docs/sky.md).
  int environment_cube_image = -1;
  bool environment_by_normal = false;
  glm::vec3 environment_color{1.0f};
  // The environment stage comes before the stage that makes the material a filter or blend layer: the
  // engine draws stages in order, so that layer filters the reflection as it filters what is behind.
  bool environment_under_layer = false;
  // Light materials (lights/...): the projected image and the falloff image.
  bool is_light_material = false;
  int light_image = -1, falloff_image = -1;
  glm::vec3 light_stage_color{1.0f};
  LightKind light_kind = LightKind::Normal;
  float light_stage_alpha = 1.0f;   // fog lights: a fog distance when > 1 (RB_FogPass)
  bool light_blend_adds = false;    // blend lights: `blend add` adds, anything else multiplies
  bool is_default = false;     // made up because the name was not found
  // The expressions behind the colours, texture matrix, alphaTest and light stage colour when any reads
  // time, parms or globals (material_registers.h); null: the fields above are the look at every frame.
  std::shared_ptr<const MaterialRegisters> registers;
};

struct Vertex {
  glm::vec3 position{0.0f};
  glm::vec2 st{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  glm::vec4 tangent{1.0f, 0.0f, 0.0f, 1.0f};  // xyz tangent, w bitangent sign
};

// A joint's rotation and position, either parent-relative or in model space (an MD5 skeleton's pose).
struct JointTransform {
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};   // column form: v' = rotation * v
  glm::vec3 position{0.0f};
  bool operator==(const JointTransform&) const = default;
};

// One influence of a joint on a vertex: the vertex gets bias * (R_joint * offset + T_joint).
struct SkinWeight {
  int joint = 0;
  float bias = 0.0f;
  glm::vec3 offset{0.0f};
};

// How an MD5 mesh's vertices follow its skeleton (Mesh::vertices is then the bind pose): vertex v sums
// weights [first_weight[v], first_weight[v] + weight_count[v]).
struct MeshSkin {
  int joint_count = 0;
  std::vector<uint32_t> first_weight, weight_count;
  std::vector<SkinWeight> weights;
};

struct Md5Anim;

// A run of triangles sharing one material, indices into Mesh::indices.
struct Surface {
  int material = -1;
  uint32_t first_index = 0, index_count = 0;
};

struct Mesh {
  std::string name;            // "_area0", an inline model's name, or a model file path
  std::vector<Vertex> vertices;
  // Per-vertex colour as the engine's idDrawVert::color bytes, RGBA8 with R in the low byte
  // (pack_rgba8); empty: every vertex white (.proc geometry, MD5). Only vertexColor materials read it.
  std::vector<uint32_t> colors;
  std::vector<uint32_t> indices;  // three per triangle, winding as in the .proc
  std::vector<Surface> surfaces;
  std::shared_ptr<const MeshSkin> skin;   // MD5 meshes: an entity with joints is skinned by it
  size_t triangle_count() const { return indices.size() / 3; }
};

// A colour in [0, 1] as the engine's four colour bytes (rounded, clamped), R in the low byte; and back.
uint32_t pack_rgba8(const glm::vec4& color);
glm::vec4 unpack_rgba8(uint32_t rgba);

enum class LightType : uint8_t { Point, Parallel, Projected };

struct Light {
  std::string name;
  std::string source;           // "file:line" of its map entity, for messages; empty for lights made in code
  LightType type = LightType::Point;
  glm::vec3 origin{0.0f};
  glm::mat3 axis{1.0f};         // columns: the light's x, y, z axes in world space
  glm::vec3 radius{300.0f};     // light_radius
  glm::vec3 center{0.0f};       // light_center (parallel: direction toward the light)
  glm::vec3 color{1.0f};        // _color
  // Projected lights, relative to origin, in the light's axis frame.
  glm::vec3 target{0.0f}, right{0.0f}, up{0.0f}, start{0.0f}, end{0.0f};
  bool has_start_end = false;
  int material = -1;            // light shader (texture key); -1: the default for its type
  bool no_shadows = false, no_specular = false;
  float shader_parms[12] = {1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};
};

struct Entity {
  std::string name, classname;
  int mesh = -1;                // into Scene::meshes; -1 for entities without geometry
  glm::vec3 origin{0.0f};
  glm::mat3 axis{1.0f};         // columns: the entity's x, y, z axes in world space
  bool no_shadows = false;
  // parm0-2 = _color, parm3 = shaderParm3 (default 1), parm4-11 = shaderParmN (default 0); materials
  // that read them (`colored`, parmN) are tinted per entity.
  float shader_parms[12] = {1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};
  std::map<std::string, std::string> keys;   // the map's keys, then its entityDef's for keys it lacks
  // Where a model file's mesh came from (empty for inline .proc models), the skin applied to it, and
  // for MD5 models the animation the entity plays (empty: none); the mesh is the bind pose.
  std::string model_file, skin, anim_file;
  std::shared_ptr<const Md5Anim> anim;       // anim_file as loaded, when it fits the mesh's skeleton
};

struct Portal {
  int area_pos = 0, area_neg = 0;
  std::vector<glm::vec3> points;
};

struct AreaNode {
  glm::vec4 plane{0.0f};        // a b c d
  int pos_child = 0, neg_child = 0;  // 0 solid, <0 area -1-child, >0 node
};

struct Scene {
  std::string name;
  std::vector<Image> images;
  std::vector<Material> materials;
  std::vector<Mesh> meshes;
  std::vector<int> area_meshes;    // the static world: one mesh per area
  std::vector<Light> lights;
  std::vector<Entity> entities;
  std::vector<Portal> portals;
  std::vector<AreaNode> nodes;
  std::vector<std::string> warnings;
  glm::vec3 player_start{0.0f}; float player_yaw = 0.0f;

  int find_material(const std::string& name) const;
  int find_mesh(const std::string& name) const;
  size_t world_triangle_count() const;
};

}  // namespace cohort::scene
