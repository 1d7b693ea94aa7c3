// The recorded delta stream: every RenderWorld call of a session, frame by frame, in a versioned,
// checksummed binary file (docs/delta-stream.md), so a session of play can be rendered again exactly.
// Recorder wraps a RenderWorld and writes each call that succeeded; Player reads a file and drives a
// RenderWorld one frame at a time. A corrupt or truncated file gives a StreamError naming the byte
// offset, the record type and what was wrong; the reader never allocates more than the file holds.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cohort/scene/render_world.h"

namespace cohort::scene {

constexpr uint32_t kDeltaStreamVersion = 7;  // 2: entities carry joints; 3: materials carry light kinds; 4: sky;
                                             // 5: vertex colours (meshes) and inverseVertexColor (materials);
                                             // 6: materials' second (vertex colour blend) diffuse image;
                                             // 7: materials' environment (texgen reflect / normal) stage
constexpr uint32_t kMaxDeltaFrameBytes = 256u << 20;  // one frame chunk's payload
constexpr uint32_t kMaxDeltaStringBytes = 4096;

enum class DeltaRecord : uint16_t {
  AddEntityDef = 1, UpdateEntityDef = 2, FreeEntityDef = 3,
  AddLightDef = 4, UpdateLightDef = 5, FreeLightDef = 6,
  DefineMaterial = 7, DefineTexture = 8, DefineModel = 9,
  RenderScene = 10, EndFrame = 11,
};
const char* delta_record_name(uint16_t type);  // "AddEntityDef", or "unknown" for other values

class StreamError : public std::runtime_error {
 public:
  StreamError(const std::string& file, uint64_t offset, const std::string& record, const std::string& what);
  uint64_t offset() const { return offset_; }
  const std::string& record() const { return record_; }  // record or chunk type; "header", "frame chunk", ...

 private:
  uint64_t offset_;
  std::string record_;
};

struct DeltaStreamHeader {
  uint32_t version = kDeltaStreamVersion;
  std::string map_name;   // the map the session was played on, as `cohort` names maps
};

class Recorder : public RenderWorldApi {
 public:
  // Writes the header at once; throws std::runtime_error when the file cannot be created.
  Recorder(RenderWorld& world, const std::filesystem::path& file, const std::string& map_name);
  ~Recorder() override;  // finishes the file if finish() was not called (errors are then only logged)

  int AddEntityDef(const RenderEntity& entity) override;
  void UpdateEntityDef(int handle, const RenderEntity& entity) override;
  void FreeEntityDef(int handle) override;
  int AddLightDef(const RenderLight& light) override;
  void UpdateLightDef(int handle, const RenderLight& light) override;
  void FreeLightDef(int handle) override;
  int DefineMaterial(const Material& material) override;
  int DefineTexture(const Image& image) override;
  int DefineModel(const Mesh& mesh) override;
  void RenderScene(const RenderView& view) override;
  void EndFrame() override;  // also writes the frame's chunk

  const RenderEntity* EntityDef(int handle) const override { return world_.EntityDef(handle); }
  const RenderLight* LightDef(int handle) const override { return world_.LightDef(handle); }
  int FindEntityDef(const std::string& name) const override { return world_.FindEntityDef(name); }
  int FindLightDef(const std::string& name) const override { return world_.FindLightDef(name); }
  const Scene& scene() const override { return world_.scene(); }

  // Write the end-of-stream marker and close. Calls of an unfinished frame are dropped with a warning.
  void finish();
  uint32_t frames_written() const { return frames_; }
  uint64_t bytes_written() const { return bytes_written_; }

 private:
  template <class Result, class... Params, class... Args>
  Result forward(DeltaRecord type, Result (RenderWorld::*call)(Params...), const Args&... args);
  template <class... Fields>
  void record(DeltaRecord type, const Fields&... fields);
  std::vector<uint8_t>& begin_record(DeltaRecord type);
  void end_record();
  void write_chunk(uint32_t tag, const std::vector<uint8_t>& payload);

  RenderWorld& world_;
  std::filesystem::path path_;
  std::ofstream out_;
  std::vector<uint8_t> frame_;      // records of the frame in progress
  size_t record_start_ = 0;
  uint32_t frames_ = 0;
  uint64_t bytes_written_ = 0;
  bool finished_ = false;
};

class Player {
 public:
  // Opens the file and checks its header; throws StreamError (or std::runtime_error if unreadable).
  explicit Player(const std::filesystem::path& file);

  const DeltaStreamHeader& header() const { return header_; }
  // Apply the next frame's calls to `world` (ending with its EndFrame). False at the end-of-stream
  // marker. Throws StreamError for a damaged file or a call the world rejects (a handle mismatch, an
  // unknown handle), naming the record's offset.
  bool play_frame(RenderWorldApi& world);
  uint32_t frames_played() const { return frames_; }

 private:
  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0, pos_ = 0;
  DeltaStreamHeader header_;
  uint32_t frames_ = 0;
  bool ended_ = false;
};

// CRC-32 (IEEE 802.3, the zlib/PNG one) of a byte range.
uint32_t crc32(const uint8_t* data, size_t size, uint32_t crc = 0);

}  // namespace cohort::scene
