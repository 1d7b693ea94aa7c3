#include <tuple>
#include <type_traits>

#include <fmt/format.h>

#include "cohort/scene/render_world_stream.h"
#include "render_world_stream_codec.h"

namespace cohort::scene {

using namespace stream_codec;

namespace {

uint32_t le32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The handle or index the recorder got back must be the one this replay gets.
void expect_same(int recorded, int replayed, const char* what) {
  if (recorded != replayed)
    throw RenderWorldError(fmt::format("recorded {} {} but the replay got {} (the stream does not match this map)",
                                       what, recorded, replayed));
}

// Reads a record as Recorder::forward wrote it (the handle or index the call returned, if it returns
// one, then its arguments), checks that nothing is left over, and makes the same call on `world`,
// which must return what the recorder got (`returned` names it).
template <class Result, class... Params>
void replay(Decoder& d, RenderWorldApi& world, Result (RenderWorldApi::*call)(Params...), const char* returned = "") {
  [[maybe_unused]] int recorded = 0;
  if constexpr (!std::is_void_v<Result>) recorded = d.i32();
  const std::tuple<std::decay_t<Params>...> args{d.read<std::decay_t<Params>>()...};
  if (d.left()) d.fail(fmt::format("{} bytes left over after the record's fields", d.left()));
  auto make_call = [&] { return std::apply([&](const auto&... a) { return (world.*call)(a...); }, args); };
  if constexpr (std::is_void_v<Result>)
    make_call();
  else
    expect_same(recorded, make_call(), returned);
}

void apply_record(DeltaRecord type, Decoder& d, RenderWorldApi& world) {
  switch (type) {
    case DeltaRecord::AddEntityDef: return replay(d, world, &RenderWorldApi::AddEntityDef, "entity handle");
    case DeltaRecord::UpdateEntityDef: return replay(d, world, &RenderWorldApi::UpdateEntityDef);
    case DeltaRecord::FreeEntityDef: return replay(d, world, &RenderWorldApi::FreeEntityDef);
    case DeltaRecord::AddLightDef: return replay(d, world, &RenderWorldApi::AddLightDef, "light handle");
    case DeltaRecord::UpdateLightDef: return replay(d, world, &RenderWorldApi::UpdateLightDef);
    case DeltaRecord::FreeLightDef: return replay(d, world, &RenderWorldApi::FreeLightDef);
    case DeltaRecord::DefineMaterial: return replay(d, world, &RenderWorldApi::DefineMaterial, "material index");
    case DeltaRecord::DefineTexture: return replay(d, world, &RenderWorldApi::DefineTexture, "texture index");
    case DeltaRecord::DefineModel: return replay(d, world, &RenderWorldApi::DefineModel, "model index");
    case DeltaRecord::RenderScene: return replay(d, world, &RenderWorldApi::RenderScene);
    case DeltaRecord::EndFrame: return replay(d, world, &RenderWorldApi::EndFrame);
  }
  d.fail("unknown record type");
}

}  // namespace

Player::Player(const std::filesystem::path& file) : path_(file.string()), in_(file, std::ios::binary) {
  if (!in_) throw std::runtime_error(fmt::format("{}: cannot open the delta stream", path_));
  in_.seekg(0, std::ios::end);
  size_ = static_cast<uint64_t>(in_.tellg());
  in_.seekg(0);
  const size_t fixed = sizeof kMagic + 8;
  uint8_t head[sizeof kMagic + 8];
  if (size_ < fixed) throw StreamError(path_, 0, "header", fmt::format("file is {} bytes, a header needs {}", size_, fixed));
  in_.read(reinterpret_cast<char*>(head), fixed);
  if (std::memcmp(head, kMagic, sizeof kMagic) != 0)
    throw StreamError(path_, 0, "header", "not a Cohort delta stream (bad magic)");
  uint32_t version = le32(head + 8);
  if (version != kDeltaStreamVersion)
    throw StreamError(path_, 8, "header", fmt::format("version {} is not supported (this build reads {})", version,
                                                       kDeltaStreamVersion));
  uint32_t body_size = le32(head + 12);
  if (body_size > kMaxDeltaStringBytes + 8 || body_size + 4 > size_ - fixed)
    throw StreamError(path_, 12, "header", fmt::format("header length {} does not fit the file", body_size));
  std::vector<uint8_t> body(body_size + 4);
  in_.read(reinterpret_cast<char*>(body.data()), std::streamsize(body.size()));
  if (!in_) throw StreamError(path_, fixed, "header", "read failed");
  if (crc32(body.data(), body_size) != le32(body.data() + body_size))
    throw StreamError(path_, fixed + body_size, "header", "CRC-32 mismatch (file corrupt)");
  Decoder d(body.data(), body_size);
  try {
    header_.version = version;
    header_.map_name = d.str();
    uint32_t flags = d.u32();
    if (flags != 0) d.fail(fmt::format("header flags 0x{:x} unknown", flags));
    if (d.left()) d.fail(fmt::format("{} unexpected bytes at the end of the header", d.left()));
  } catch (const DecodeError& e) {
    throw StreamError(path_, fixed + e.at, "header", e.what());
  }
  pos_ = fixed + body.size();
}

bool Player::play_frame(RenderWorldApi& world) {
  if (ended_) return false;
  const uint64_t chunk_at = pos_;
  if (size_ - pos_ < kChunkHeaderBytes)
    throw StreamError(path_, pos_, "frame chunk",
                      size_ == pos_ ? "truncated: the end-of-stream marker is missing"
                                    : fmt::format("truncated: a chunk header needs {} bytes, {} left", kChunkHeaderBytes,
                                                  size_ - pos_));
  uint8_t head[kChunkHeaderBytes];
  in_.read(reinterpret_cast<char*>(head), kChunkHeaderBytes);
  if (!in_) throw StreamError(path_, pos_, "frame chunk", "read failed");
  pos_ += kChunkHeaderBytes;
  uint32_t tag = le32(head), index = le32(head + 4), length = le32(head + 8), crc = le32(head + 12);
  if (tag != kFrameTag && tag != kDoneTag)
    throw StreamError(path_, chunk_at, "frame chunk", fmt::format("unknown chunk tag 0x{:08x}", tag));
  const char* chunk_name = tag == kFrameTag ? "frame chunk" : "end-of-stream marker";
  if (index != frames_)
    throw StreamError(path_, chunk_at + 4, chunk_name, fmt::format("frame number {} where {} was expected", index, frames_));
  if (length > kMaxDeltaFrameBytes)
    throw StreamError(path_, chunk_at + 8, chunk_name, fmt::format("payload length {} over the limit {}", length,
                                                                  kMaxDeltaFrameBytes));
  if (length > size_ - pos_)
    throw StreamError(path_, chunk_at + 8, chunk_name,
                      fmt::format("truncated: payload length {} but only {} bytes left in the file", length, size_ - pos_));
  if (tag == kDoneTag) {
    if (length != 0) throw StreamError(path_, chunk_at + 8, chunk_name, "carries a payload");
    if (crc != crc32(nullptr, 0)) throw StreamError(path_, chunk_at + 12, chunk_name, "CRC-32 mismatch (file corrupt)");
    if (pos_ != size_)
      throw StreamError(path_, pos_, chunk_name, fmt::format("{} bytes follow the end of the stream", size_ - pos_));
    ended_ = true;
    return false;
  }
  std::vector<uint8_t> payload(length);
  in_.read(reinterpret_cast<char*>(payload.data()), length);
  if (!in_) throw StreamError(path_, pos_, chunk_name, "read failed");
  const uint64_t payload_at = pos_;
  pos_ += length;
  if (crc32(payload.data(), length) != crc)
    throw StreamError(path_, chunk_at + 12, chunk_name, fmt::format("frame {}: CRC-32 mismatch (file corrupt)", index));

  // The checksum matched, so what follows is what the recorder wrote, unless a writer was buggy or the
  // file was forged: every length is still checked.
  size_t at = 0;
  bool ended_frame = false;
  while (at < length) {
    const uint64_t record_at = payload_at + at;
    if (ended_frame) throw StreamError(path_, record_at, "EndFrame", "records follow the frame's EndFrame");
    if (length - at < kRecordHeaderBytes)
      throw StreamError(path_, record_at, chunk_name, "truncated record header");
    uint16_t type = uint16_t(payload[at] | payload[at + 1] << 8);
    uint16_t reserved = uint16_t(payload[at + 2] | payload[at + 3] << 8);
    uint32_t body = le32(payload.data() + at + 4);
    const char* name = delta_record_name(type);
    if (reserved != 0) throw StreamError(path_, record_at + 2, name, "reserved field is not zero");
    if (body > length - at - kRecordHeaderBytes)
      throw StreamError(path_, record_at + 4, name, fmt::format("body length {} runs past the frame chunk", body));
    Decoder d(payload.data() + at + kRecordHeaderBytes, body);
    try {
      apply_record(static_cast<DeltaRecord>(type), d, world);
    } catch (const DecodeError& e) {
      throw StreamError(path_, record_at + kRecordHeaderBytes + e.at, name, e.what());
    } catch (const RenderWorldError& e) {
      throw StreamError(path_, record_at, name, e.what());
    }
    ended_frame = static_cast<DeltaRecord>(type) == DeltaRecord::EndFrame;
    at += kRecordHeaderBytes + body;
  }
  if (!ended_frame) throw StreamError(path_, payload_at + length, chunk_name, "frame does not end with EndFrame");
  ++frames_;
  return true;
}

}  // namespace cohort::scene
