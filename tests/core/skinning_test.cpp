// Skinned characters through the one commit path: WorldSync poses an MD5 character from its entity's
// joints with the kernel's skinning routines (kernel/skinning.h) and refits its BLAS; a tracer's copy
// applying the commits ends with the same bytes; the commit per frame carries joints, not vertices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "cohort/commit/array_diff.h"
#include "cohort/commit/commit_buffer.h"
#include "cohort/core/bvh.h"
#include "cohort/core/world_sync.h"
#include "cohort/kernel/bvh_traverse.h"
#include "cohort/scene/md5.h"
#include "cohort/scene/render_world.h"

using namespace cohort;

namespace {

std::string read_text(const std::string& relative) {
  std::ifstream in(std::filesystem::path(COHORT_SOURCE_DIR) / relative, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

const char* kMeshFile = "assets/testmap/models/testmap/walker.md5mesh";
const char* kAnimFile = "assets/testmap/models/testmap/walker_walk.md5anim";

// The walker's md5mesh with its mesh block repeated `copies` times: the same skeleton, more vertices.
scene::Md5Mesh walker_mesh(int copies = 1) {
  std::string text = read_text(kMeshFile);
  const size_t at = text.find("mesh {");
  EXPECT_NE(at, std::string::npos);
  std::string block = text.substr(at);
  for (int c = 1; c < copies; ++c) text += "\n" + block;
  const size_t count = text.find("numMeshes 1");
  EXPECT_NE(count, std::string::npos);
  text.replace(count, 11, "numMeshes " + std::to_string(copies));
  return scene::parse_md5mesh(text, kMeshFile);
}

scene::Md5Anim walker_anim() { return scene::parse_md5anim(read_text(kAnimFile), kAnimFile); }

// A scene holding the mesh (bind pose, with its skin) and one entity drawing it.
scene::Scene character_scene(const scene::Md5Mesh& md5) {
  scene::Scene s;
  s.name = "skinning";
  scene::Mesh mesh = scene::skin_md5(md5, scene::bind_pose(md5)).mesh;
  mesh.skin = std::make_shared<const scene::MeshSkin>(scene::md5_mesh_skin(md5));
  s.meshes.push_back(std::move(mesh));
  scene::Entity e;
  e.name = "walker";
  e.mesh = 0;
  e.origin = {10.0f, -4.0f, 2.0f};
  s.entities.push_back(e);
  return s;
}

scene::RenderEntity posed(const scene::RenderWorld& world, std::vector<scene::JointTransform> joints) {
  scene::RenderEntity def = *world.EntityDef(0);
  def.joints = std::move(joints);
  return def;
}

float max_abs(const float* a, const glm::vec3& b) {
  return std::max({std::fabs(a[0] - b.x), std::fabs(a[1] - b.y), std::fabs(a[2] - b.z)});
}

}  // namespace

TEST(Skinning, PortableRoutineEqualsSkinMd5OverTheWalkAnim) {
  const scene::Md5Mesh md5 = walker_mesh();
  const scene::Md5Anim anim = walker_anim();
  scene::RenderWorld world(character_scene(md5));
  core::WorldSync sync(world);
  world.TakeChanges();
  commit::TracerScene copy = *sync.snapshot();
  for (int time_ms : {0, 130, 410, 777, 1000, 1666}) {
    const std::vector<scene::JointTransform> pose = scene::anim_pose(anim, time_ms);
    world.UpdateEntityDef(0, posed(world, pose));
    commit::CommitBuffer records = sync.sync(world.TakeChanges(), uint64_t(time_ms + 1));
    commit::apply_commit(records, copy);
    const commit::TracerScene& master = sync.master();
    ASSERT_EQ(master.skins.size(), 1u);
    const KSkin skin = master.skins[0];
    const scene::Mesh expected = scene::skin_md5(md5, pose).mesh;
    ASSERT_EQ(skin.vertex_count, expected.vertices.size());
    float position_error = 0.0f, normal_error = 0.0f, tangent_error = 0.0f;
    int sign_mismatches = 0;
    for (uint32_t v = 0; v < skin.vertex_count; ++v) {
      const KVertex& got = master.vertices[skin.vertex_offset + v];
      const scene::Vertex& want = expected.vertices[v];
      position_error = std::max(position_error, max_abs(got.pos, want.position));
      normal_error = std::max(normal_error, max_abs(got.normal, want.normal));
      tangent_error = std::max(tangent_error, max_abs(got.tangent, glm::vec3(want.tangent)));
      sign_mismatches += got.bitangent_sign != want.tangent.w;
    }
    EXPECT_LT(position_error, 1e-4f) << "at " << time_ms << " ms";
    EXPECT_LT(normal_error, 1e-4f) << "at " << time_ms << " ms";
    EXPECT_LT(tangent_error, 1e-3f) << "at " << time_ms << " ms";
    EXPECT_EQ(sign_mismatches, 0) << "at " << time_ms << " ms";
    std::string where;
    EXPECT_TRUE(commit::same_tracer_scene(copy, master, &where)) << "the tracer copy differs at " << where;
  }
  // The pose really moved the vertices: the anim's frames are not the bind pose.
  const scene::Mesh bind = scene::skin_md5(md5, scene::bind_pose(md5)).mesh;
  const KSkin skin = sync.master().skins[0];
  float moved = 0.0f;
  for (uint32_t v = 0; v < skin.vertex_count; ++v)
    moved = std::max(moved, max_abs(sync.master().vertices[skin.vertex_offset + v].pos, bind.vertices[v].position));
  EXPECT_GT(moved, 1.0f);
}

TEST(Skinning, RefitBlasHitsEqualBruteForce) {
  const scene::Md5Mesh md5 = walker_mesh();
  const scene::Md5Anim anim = walker_anim();
  scene::RenderWorld world(character_scene(md5));
  core::WorldSync sync(world);
  world.TakeChanges();
  std::mt19937 rng(5);
  for (int time_ms : {250, 600, 950}) {
    scene::RenderEntity def = posed(world, scene::anim_pose(anim, time_ms));
    def.origin.x += float(time_ms) * 0.01f;  // it also walks: the TLAS follows
    world.UpdateEntityDef(0, def);
    sync.sync(world.TakeChanges(), uint64_t(time_ms));
    const commit::TracerScene& s = sync.master();
    const KSkin skin = s.skins[0];
    const KBlas blas = s.blases[skin.blas];
    // The refit root bounds the posed vertices exactly.
    const KBvhNode& root = s.blas_nodes[blas.node_offset];
    for (int a = 0; a < 3; ++a) {
      float lo = 1e30f, hi = -1e30f;
      for (uint32_t v = 0; v < skin.vertex_count; ++v) {
        lo = std::min(lo, s.vertices[skin.vertex_offset + v].pos[a]);
        hi = std::max(hi, s.vertices[skin.vertex_offset + v].pos[a]);
      }
      EXPECT_EQ(root.bmin[a], lo);
      EXPECT_EQ(root.bmax[a], hi);
    }
    const KSceneRef ref{s.vertices.data(), s.triangles.data(), s.blas_nodes.data(), s.blases.data(),
                        s.instances.data(), s.tlas_nodes.data(), kuint(s.instances.size()), kuint(s.tlas_nodes.size())};
    const KInstance& inst = s.instances.at(0);
    const KVec3 centre = v3((root.bmin[0] + root.bmax[0]) * 0.5f + inst.object_to_world[3],
                            (root.bmin[1] + root.bmax[1]) * 0.5f + inst.object_to_world[7],
                            (root.bmin[2] + root.bmax[2]) * 0.5f + inst.object_to_world[11]);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    int hits = 0;
    for (int r = 0; r < 2000; ++r) {
      KVec3 o = v3_add(centre, v3(unit(rng) * 150.0f, unit(rng) * 150.0f, unit(rng) * 150.0f));
      KVec3 target = v3_add(centre, v3(unit(rng) * 30.0f, unit(rng) * 30.0f, unit(rng) * 50.0f));
      KVec3 d = v3_normalize(v3_sub(target, o));
      float best = 1e30f;
      kuint best_tri = K_NONE;
      for (kuint i = 0; i < s.instances.size(); ++i) {
        const KInstance& in = s.instances[i];
        KVec3 lo = xform_point_g(in.world_to_object, o), ld = xform_vector_g(in.world_to_object, d);
        const KBlas& b = s.blases[in.blas];
        for (kuint t = b.tri_offset; t < b.tri_offset + b.tri_count; ++t) {
          float th, u, v;
          if (k_bvh_hit_triangle(ref, t, lo, ld, 1e-4f, best, &th, &u, &v) && th < best) best = th, best_tri = t;
        }
      }
      KHit hit;
      const int found = k_bvh_closest(ref, 0, o, d, 1e-4f, 1e30f, K_MASK_PRIMARY, &hit);
      ASSERT_EQ(found != 0, best_tri != K_NONE) << "ray " << r << " at " << time_ms << " ms";
      if (found) {
        EXPECT_EQ(hit.t, best);
        ++hits;
      }
    }
    EXPECT_GT(hits, 200);
  }
}

// Per frame the character costs its joints: the same skeleton over three times the vertices sends the
// same bytes, and the skin's record is its joints.
TEST(Skinning, CommitBytesPerFrameFollowJointsNotVertices) {
  const scene::Md5Anim anim = walker_anim();
  size_t frame_bytes[2] = {0, 0};
  size_t vertex_counts[2] = {0, 0};
  for (int copies : {1, 3}) {
    const scene::Md5Mesh md5 = walker_mesh(copies);
    scene::RenderWorld world(character_scene(md5));
    core::WorldSync sync(world);
    world.TakeChanges();
    world.UpdateEntityDef(0, posed(world, scene::anim_pose(anim, 100)));
    commit::CommitBuffer first = sync.sync(world.TakeChanges(), 1);
    EXPECT_EQ(first.skin_uploads().size(), 1u);  // the bind-pose data, once
    for (int frame = 2; frame < 8; ++frame) {
      world.UpdateEntityDef(0, posed(world, scene::anim_pose(anim, 100 + frame * 40)));
      commit::CommitBuffer records = sync.sync(world.TakeChanges(), uint64_t(frame));
      ASSERT_EQ(records.skin_joints().size(), 1u);
      EXPECT_EQ(records.skin_joints().begin()->second.size(), md5.joints.size());
      EXPECT_TRUE(records.skin_uploads().empty());
      EXPECT_TRUE(records.blas_uploads().empty()) << "no vertices or nodes travel while the refit holds";
      EXPECT_EQ(sync.last_stats().skin_rebuilds, 0u);
      const size_t bytes = records.bytes();
      if (frame_bytes[copies == 3] == 0) frame_bytes[copies == 3] = bytes;
      EXPECT_LE(bytes, frame_bytes[copies == 3] + 64);
    }
    vertex_counts[copies == 3] = sync.master().skins[0].vertex_count;
  }
  EXPECT_EQ(vertex_counts[1], 3 * vertex_counts[0]);
  EXPECT_EQ(frame_bytes[0], frame_bytes[1]) << "bytes per frame must not grow with the vertices";
  const size_t joints_bytes = walker_mesh().joints.size() * sizeof(KJoint) + commit::kRecordHeaderBytes;
  EXPECT_LT(frame_bytes[0], joints_bytes + 2048) << "joints plus the small TLAS and instance records";
  EXPECT_LT(frame_bytes[0], vertex_counts[0] * sizeof(KVertex));
}

// A joint count other than the skin's is not drawn (the engine's rule), and said once.
TEST(Skinning, WrongJointCountIsNotDrawn) {
  const scene::Md5Mesh md5 = walker_mesh();
  scene::RenderWorld world(character_scene(md5));
  core::WorldSync sync(world);
  world.TakeChanges();
  world.UpdateEntityDef(0, posed(world, std::vector<scene::JointTransform>(md5.joints.size() + 1)));
  sync.sync(world.TakeChanges(), 1);
  for (const KInstance& inst : sync.master().instances) EXPECT_NE(inst.entity, 0u);
  world.UpdateEntityDef(0, posed(world, scene::bind_pose(md5)));
  sync.sync(world.TakeChanges(), 2);
  bool drawn = false;
  for (const KInstance& inst : sync.master().instances) drawn |= inst.entity == 0u;
  EXPECT_TRUE(drawn);
}

// A skin whose data points outside the pools is refused when the commit is applied (the tracer then asks
// for a full resync), before any skinning routine follows it.
TEST(Skinning, BrokenSkinUploadIsRefused) {
  const scene::Md5Mesh md5 = walker_mesh();
  scene::RenderWorld world(character_scene(md5));
  core::WorldSync sync(world);
  commit::TracerScene copy = *sync.snapshot();
  world.TakeChanges();
  world.UpdateEntityDef(0, posed(world, scene::bind_pose(md5)));
  const commit::CommitBuffer records = sync.sync(world.TakeChanges(), 1);
  ASSERT_EQ(records.skin_uploads().size(), 1u);
  for (int breakage = 0; breakage < 4; ++breakage) {
    commit::CommitBuffer broken;
    for (const commit::BlasUpload& b : records.blas_uploads()) broken.add_blas(b);
    commit::SkinUpload up = records.skin_uploads()[0];
    if (breakage == 0) up.triangles[3].v1 = up.skin.vertex_count;       // a vertex past the skin's
    if (breakage == 3) up.adjacency[3] = up.skin.triangle_count;        // a triangle past the skin's
    if (breakage == 1) up.vertices[5].first_weight = uint32_t(up.weights.size());  // weights past the pool
    if (breakage == 2) up.skin.blas = 99;                                // no such BLAS
    broken.add_skin(up);
    broken.set_skin_joints(up.skin_index, records.skin_joints().begin()->second);
    commit::TracerScene target = copy;
    EXPECT_THROW(commit::apply_commit(broken, target), std::invalid_argument) << "breakage " << breakage;
  }
  commit::TracerScene target = copy;
  EXPECT_NO_THROW(commit::apply_commit(records, target));
}

// Skinning moves positions only: a character whose mesh carries vertex colours keeps them, in the
// master and in a tracer's copy, through every pose, while its vertices move.
TEST(Skinning, VertexColoursStayWithTheirVerticesThroughPoses) {
  const scene::Md5Mesh md5 = walker_mesh();
  scene::Scene s = character_scene(md5);
  const size_t count = s.meshes[0].vertices.size();
  for (size_t v = 0; v < count; ++v) s.meshes[0].colors.push_back(0xFF000000u | uint32_t(v * 2654435761u & 0xFFFFFFu));
  const std::vector<uint32_t> colours = s.meshes[0].colors;
  scene::RenderWorld world(s);
  core::WorldSync sync(world);
  world.TakeChanges();
  commit::TracerScene copy;
  commit::apply_commit(commit::CommitBuffer::full(sync.snapshot(), 0), copy);
  const scene::Md5Anim anim = walker_anim();
  world.UpdateEntityDef(0, posed(world, scene::anim_pose(anim, 0)));   // the first pose makes the skin
  commit::apply_commit(sync.sync(world.TakeChanges(), 1), copy);
  ASSERT_EQ(sync.master().skins.size(), 1u);
  const KSkin skin = sync.master().skins[0];
  ASSERT_EQ(skin.vertex_count, count);
  const std::vector<KVertex> first_pose(sync.master().vertices.begin() + skin.vertex_offset,
                                  sync.master().vertices.begin() + skin.vertex_offset + count);
  for (int time_ms : {130, 777}) {
    world.UpdateEntityDef(0, posed(world, scene::anim_pose(anim, time_ms)));
    commit::apply_commit(sync.sync(world.TakeChanges(), uint64_t(time_ms + 1)), copy);
    for (const commit::TracerScene* t : {&sync.master(), static_cast<const commit::TracerScene*>(&copy)}) {
      ASSERT_EQ(t->vertex_colors.size(), t->vertices.size());
      EXPECT_TRUE(std::equal(colours.begin(), colours.end(), t->vertex_colors.begin() + skin.vertex_offset))
          << "at " << time_ms << " ms";
    }
    float moved = 0.0f;
    for (size_t v = 0; v < count; ++v)
      moved = std::max(moved, max_abs(copy.vertices[skin.vertex_offset + v].pos,
                                      glm::vec3(first_pose[v].pos[0], first_pose[v].pos[1], first_pose[v].pos[2])));
    EXPECT_GT(moved, 1.0f) << "the pose at " << time_ms << " ms moved nothing";
  }
}
