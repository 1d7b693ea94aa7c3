#include <type_traits>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "cohort/scene/render_world_stream.h"
#include "render_world_stream_codec.h"

namespace cohort::scene {

using namespace stream_codec;

StreamError::StreamError(const std::string& file, uint64_t offset, const std::string& record, const std::string& what)
    : std::runtime_error(fmt::format("{}: offset {}: {}: {}", file, offset, record, what)),
      offset_(offset),
      record_(record) {}

Recorder::Recorder(RenderWorld& world, const std::filesystem::path& file, const std::string& map_name)
    : world_(world), path_(file), out_(file, std::ios::binary | std::ios::trunc) {
  if (!out_) throw std::runtime_error(fmt::format("{}: cannot create the delta stream file", file.string()));
  if (map_name.size() > kMaxDeltaStringBytes) throw std::invalid_argument("Recorder: map name too long");
  std::vector<uint8_t> header;
  Encoder e(header);
  e.bytes(reinterpret_cast<const uint8_t*>(kMagic), sizeof kMagic);
  e.u32(kDeltaStreamVersion);
  std::vector<uint8_t> body;
  Encoder b(body);
  b.str(map_name);
  b.u32(0);  // flags, none defined in version 1
  e.u32(static_cast<uint32_t>(body.size()));
  e.bytes(body.data(), body.size());
  e.u32(crc32(body.data(), body.size()));
  out_.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size()));
  bytes_written_ += header.size();
}

Recorder::~Recorder() {
  if (finished_) return;
  try {
    finish();
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

std::vector<uint8_t>& Recorder::begin_record(DeltaRecord type) {
  if (finished_) throw std::logic_error("Recorder: call after finish()");
  record_start_ = frame_.size();
  Encoder e(frame_);
  e.u16(static_cast<uint16_t>(type));
  e.u16(0);
  e.u32(0);  // body length, patched by end_record
  return frame_;
}

void Recorder::end_record() {
  uint32_t body = static_cast<uint32_t>(frame_.size() - record_start_ - kRecordHeaderBytes);
  for (int i = 0; i < 4; ++i) frame_[record_start_ + 4 + i] = uint8_t(body >> (8 * i));
  if (frame_.size() > kMaxDeltaFrameBytes)
    throw std::length_error(fmt::format("Recorder: frame {} is over {} bytes", frames_, kMaxDeltaFrameBytes));
}

void Recorder::write_chunk(uint32_t tag, const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> head;
  Encoder e(head);
  e.u32(tag);
  e.u32(frames_);
  e.u32(static_cast<uint32_t>(payload.size()));
  e.u32(crc32(payload.data(), payload.size()));
  out_.write(reinterpret_cast<const char*>(head.data()), std::streamsize(head.size()));
  out_.write(reinterpret_cast<const char*>(payload.data()), std::streamsize(payload.size()));
  if (!out_) throw std::runtime_error(fmt::format("{}: write failed", path_.string()));
  bytes_written_ += head.size() + payload.size();
}

template <class... Fields>
void Recorder::record(DeltaRecord type, const Fields&... fields) {
  Encoder(begin_record(type)).fields(fields...);
  end_record();
}

// Each call goes to the world first; only a call the world accepted is written down: the handle or
// index it returned, if it returns one, then its arguments.
template <class Result, class... Params, class... Args>
Result Recorder::forward(DeltaRecord type, Result (RenderWorld::*call)(Params...), const Args&... args) {
  if constexpr (std::is_void_v<Result>) {
    (world_.*call)(args...);
    record(type, args...);
  } else {
    const Result returned = (world_.*call)(args...);
    record(type, returned, args...);
    return returned;
  }
}

int Recorder::AddEntityDef(const RenderEntity& entity) {
  return forward(DeltaRecord::AddEntityDef, &RenderWorld::AddEntityDef, entity);
}
void Recorder::UpdateEntityDef(int handle, const RenderEntity& entity) {
  forward(DeltaRecord::UpdateEntityDef, &RenderWorld::UpdateEntityDef, handle, entity);
}
void Recorder::FreeEntityDef(int handle) { forward(DeltaRecord::FreeEntityDef, &RenderWorld::FreeEntityDef, handle); }
int Recorder::AddLightDef(const RenderLight& light) {
  return forward(DeltaRecord::AddLightDef, &RenderWorld::AddLightDef, light);
}
void Recorder::UpdateLightDef(int handle, const RenderLight& light) {
  forward(DeltaRecord::UpdateLightDef, &RenderWorld::UpdateLightDef, handle, light);
}
void Recorder::FreeLightDef(int handle) { forward(DeltaRecord::FreeLightDef, &RenderWorld::FreeLightDef, handle); }
int Recorder::DefineMaterial(const Material& material) {
  return forward(DeltaRecord::DefineMaterial, &RenderWorld::DefineMaterial, material);
}
int Recorder::DefineTexture(const Image& image) {
  return forward(DeltaRecord::DefineTexture, &RenderWorld::DefineTexture, image);
}
int Recorder::DefineModel(const Mesh& mesh) { return forward(DeltaRecord::DefineModel, &RenderWorld::DefineModel, mesh); }
void Recorder::RenderScene(const RenderView& view) { forward(DeltaRecord::RenderScene, &RenderWorld::RenderScene, view); }

void Recorder::EndFrame() {
  forward(DeltaRecord::EndFrame, &RenderWorld::EndFrame);
  write_chunk(kFrameTag, frame_);
  frame_.clear();
  ++frames_;
}

void Recorder::finish() {
  if (finished_) return;
  if (!frame_.empty())
    spdlog::warn("{}: {} bytes of calls after the last EndFrame are not recorded", path_.string(), frame_.size());
  frame_.clear();
  write_chunk(kDoneTag, {});
  finished_ = true;
  out_.close();
  if (!out_) throw std::runtime_error(fmt::format("{}: closing the delta stream failed", path_.string()));
}

}  // namespace cohort::scene
