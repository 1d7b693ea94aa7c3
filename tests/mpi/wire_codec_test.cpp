// The MPI wire codec (tracers/mpi/mpi_wire.h) on its own: what it encodes decodes to the same scene
// changes, and every malformed or truncated message is refused with a reason instead of being applied.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>

#include "cohort/commit/array_diff.h"
#include "cohort/test_support/scene_churn.h"
#include "cohort/tracers/mpi_wire.h"

using namespace cohort;
using namespace cohort::tracers;

namespace {

commit::TracerScene applied(const commit::CommitBuffer& c, commit::TracerScene scene) {
  commit::apply_commit(c, scene);
  return scene;
}

// Every strict prefix of `payload` must be refused by `decode`.
template <class Decode> void expect_every_prefix_refused(const std::vector<uint8_t>& payload, Decode decode) {
  const size_t stride = payload.size() > 4096 ? payload.size() / 2048 : 1;
  for (size_t n = 0; n < payload.size(); n += stride) {
    std::vector<uint8_t> cut(payload.begin(), payload.begin() + long(n));
    EXPECT_THROW(decode(cut), wire::WireError) << "a prefix of " << n << " of " << payload.size() << " bytes";
  }
}

std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const wire::WireError& e) {
    return e.what();
  }
  return "(accepted)";
}

}  // namespace

TEST(WireCodec, IncrementalCommitsDecodeToTheSameSceneChanges) {
  test::SceneChurn churn(11);
  commit::TracerScene direct = churn.master(), through_wire = churn.master();
  for (uint64_t frame = 1; frame <= 40; ++frame) {
    const commit::CommitBuffer records = churn.step(frame, frame % 7 == 0);
    const commit::CommitBuffer decoded = wire::decode_commit(wire::encode_commit(records));
    EXPECT_EQ(decoded.frame(), frame);
    EXPECT_EQ(decoded.record_count(), records.record_count());
    EXPECT_EQ(decoded.bytes(), records.bytes());
    commit::apply_commit(records, direct);
    commit::apply_commit(decoded, through_wire);
    std::string where;
    ASSERT_TRUE(commit::same_tracer_scene(direct, through_wire, &where)) << "frame " << frame << ": " << where;
  }
  std::string where;
  EXPECT_TRUE(commit::same_tracer_scene(through_wire, churn.master(), &where)) << where;
}

TEST(WireCodec, FullResyncCarriesTheWholeScene) {
  test::SceneChurn churn(3);
  for (uint64_t frame = 1; frame <= 5; ++frame) churn.step(frame, true);
  auto scene = std::make_shared<commit::TracerScene>(churn.master());
  const commit::CommitBuffer full = commit::CommitBuffer::full(scene, 5);
  const commit::CommitBuffer decoded = wire::decode_commit(wire::encode_commit(full));
  ASSERT_TRUE(decoded.is_full_resync());
  EXPECT_EQ(decoded.frame(), 5u);
  std::string where;
  EXPECT_TRUE(commit::same_tracer_scene(*decoded.full_scene(), *scene, &where)) << where;
  EXPECT_EQ(std::memcmp(&decoded.full_scene()->camera, &scene->camera, sizeof(KCamera)), 0);
}

// A channel that took a full resync and then more frames' records before its tracer's job holds a full
// buffer with records on top: both must travel.
TEST(WireCodec, FullResyncWithRecordsOnTopKeepsTheRecords) {
  test::SceneChurn churn(13);
  for (uint64_t frame = 1; frame <= 3; ++frame) churn.step(frame, true);
  auto base = std::make_shared<commit::TracerScene>(churn.master());
  commit::CommitBuffer pending = commit::CommitBuffer::full(base, 3);
  for (uint64_t frame = 4; frame <= 6; ++frame) pending.merge(churn.step(frame, frame == 5));
  ASSERT_TRUE(pending.is_full_resync());
  ASSERT_GT(pending.record_count(), 0u);
  std::string where;
  const commit::CommitBuffer decoded = wire::decode_commit(wire::encode_commit(pending));
  EXPECT_EQ(decoded.record_count(), pending.record_count());
  EXPECT_TRUE(commit::same_tracer_scene(applied(decoded, {}), churn.master(), &where)) << where;
  // The same as a full resync to the node's own copy of `base`: only camera, version and records travel.
  const std::vector<uint8_t> local = wire::encode_full_local(pending);
  EXPECT_LT(local.size(), wire::encode_commit(pending).size());
  const commit::CommitBuffer rebuilt = wire::decode_full_local(local, base);
  EXPECT_TRUE(commit::same_tracer_scene(applied(rebuilt, {}), churn.master(), &where)) << where;
  expect_every_prefix_refused(local, [&](const auto& p) { return wire::decode_full_local(p, base); });
}

TEST(WireCodec, TruncatedCommitsAreRefused) {
  test::SceneChurn churn(5);
  const commit::CommitBuffer records = churn.step(1, true);
  expect_every_prefix_refused(wire::encode_commit(records), [](const auto& p) { return wire::decode_commit(p); });
  auto scene = std::make_shared<commit::TracerScene>(churn.master());
  expect_every_prefix_refused(wire::encode_commit(commit::CommitBuffer::full(scene, 1)),
                              [](const auto& p) { return wire::decode_commit(p); });
}

TEST(WireCodec, MalformedCommitsAreRefusedWithTheReason) {
  test::SceneChurn churn(9);
  commit::CommitBuffer records = churn.step(1, false);
  std::vector<uint8_t> payload = wire::encode_commit(records);
  // The first record's tag (after the 1-byte full flag and 8-byte frame) made unknown.
  std::vector<uint8_t> bad_tag = payload;
  const uint32_t unknown = 999;
  std::memcpy(bad_tag.data() + 9, &unknown, 4);
  EXPECT_NE(refusal([&] { wire::decode_commit(bad_tag); }).find("unknown record tag 999"), std::string::npos);

  std::vector<uint8_t> bad_flag = payload;
  bad_flag[0] = 7;
  EXPECT_NE(refusal([&] { wire::decode_commit(bad_flag); }).find("full-resync flag 7"), std::string::npos);

  std::vector<uint8_t> trailing = payload;
  trailing.push_back(0);
  EXPECT_NE(refusal([&] { wire::decode_commit(trailing); }).find("left over"), std::string::npos);

  // A TLAS whose element count claims far more than the message holds.
  commit::CommitBuffer tlas_only;
  tlas_only.set_tlas(std::vector<KBvhNode>(3));
  std::vector<uint8_t> huge = wire::encode_commit(tlas_only);
  const uint64_t lie = uint64_t(1) << 40;
  std::memcpy(huge.data() + 9 + 4, &lie, 8);
  EXPECT_NE(refusal([&] { wire::decode_commit(huge); }).find("do not fit"), std::string::npos);

  // A whole scene whose instance names a BLAS that does not exist.
  auto scene = std::make_shared<commit::TracerScene>(churn.master());
  ASSERT_FALSE(scene->instances.empty());
  scene->instances[0].blas = uint32_t(scene->blases.size()) + 5;
  EXPECT_NE(refusal([&] { wire::decode_commit(wire::encode_commit(commit::CommitBuffer::full(scene, 2))); })
                .find("names BLAS"),
            std::string::npos);
}

TEST(WireCodec, HeadersAreCheckedBeforeThePayload) {
  const std::vector<uint8_t> payload = wire::encode_text("hello there");
  const std::vector<uint8_t> good = wire::frame_message(wire::Kind::load_failed, 42, payload);
  const wire::Message m = wire::parse_message(good.data(), good.size());
  EXPECT_EQ(m.kind, wire::Kind::load_failed);
  EXPECT_EQ(m.sequence, 42u);
  EXPECT_EQ(wire::decode_text(m.payload), "hello there");

  auto refused = [](std::vector<uint8_t> bytes) {
    try {
      wire::parse_message(bytes.data(), bytes.size());
    } catch (const wire::WireError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  std::vector<uint8_t> bad_magic = good;
  bad_magic[0] ^= 0xff;
  EXPECT_NE(refused(bad_magic).find("bad magic"), std::string::npos);
  std::vector<uint8_t> other_protocol = good;
  other_protocol[4] = 9;
  EXPECT_NE(refused(other_protocol).find("protocol version 9"), std::string::npos);
  std::vector<uint8_t> unknown_kind = good;
  unknown_kind[6] = 77;
  EXPECT_NE(refused(unknown_kind).find("unknown message kind 77"), std::string::npos);
  std::vector<uint8_t> truncated(good.begin(), good.end() - 3);
  EXPECT_NE(refused(truncated).find("announces"), std::string::npos);
  for (size_t n = 0; n < sizeof(wire::Header); ++n)
    EXPECT_NE(refused(std::vector<uint8_t>(good.begin(), good.begin() + long(n))).find("shorter than"),
              std::string::npos);
}

TEST(WireCodec, BandRowsTravelAsTheBandFormatsBytes) {
  for (core::BandFormat format : {core::BandFormat::rgb16f, core::BandFormat::rgba32f}) {
    core::BandBuffer band(8, 5, format);
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 8; ++x) {
        const float rgba[4] = {float(x), float(y) * 0.5f, 0.25f, 1.0f};
        band.store(y, x, rgba, 1);
      }
    const std::vector<float> work = {3.0f, 4.0f, 5.0f};
    const std::vector<uint8_t> payload = wire::encode_band_rows(band, 1, 4, 2.5, work);
    EXPECT_EQ(payload.size(), 4 * 4 + 8 + 8 + 3 * 4 + 8 + 3 * band.row_bytes() + 8);
    const wire::BandRows rows = wire::decode_band_rows(payload);
    EXPECT_EQ(rows.row_begin, 1u);
    EXPECT_EQ(rows.row_end, 4u);
    EXPECT_EQ(rows.format, format);
    EXPECT_EQ(rows.device_ms, 2.5);
    EXPECT_EQ(rows.row_work, work);
    ASSERT_EQ(rows.pixels.size(), 3 * band.row_bytes());
    EXPECT_EQ(std::memcmp(rows.pixels.data(), band.row(1), rows.pixels.size()), 0);
    expect_every_prefix_refused(payload, [](const auto& p) { return wire::decode_band_rows(p); });
  }
  // Rows whose pixel bytes do not match their announced size are refused.
  core::BandBuffer band(8, 5, core::BandFormat::rgb16f);
  std::vector<uint8_t> payload = wire::encode_band_rows(band, 0, 2, 1.0, {});
  const uint32_t wider = 9;
  std::memcpy(payload.data() + 8, &wider, 4);
  EXPECT_NE(refusal([&] { wire::decode_band_rows(payload); }).find("pixel bytes"), std::string::npos);
}

TEST(WireCodec, TheNodesOneBufferMessageIsTheFramedPayloadAndDecodesInPlace) {
  core::BandBuffer band(8, 6, core::BandFormat::rgb16f);
  band.enable_aux(true);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) {
      const float rgba[4] = {float(x), float(y), 0.5f, 1.0f};
      band.store(y, x, rgba, 1);
      band.aux_row(y)[x].depth = float(10 * y + x);
    }
  const std::vector<float> work = {1.0f, 2.0f};
  const std::vector<uint8_t> message = wire::band_rows_message(77, band, 2, 4, 1.5, work);
  EXPECT_EQ(message, wire::frame_message(wire::Kind::band_rows, 77, wire::encode_band_rows(band, 2, 4, 1.5, work)));
  const wire::Message m = wire::parse_message(message.data(), message.size());
  EXPECT_EQ(m.kind, wire::Kind::band_rows);
  EXPECT_EQ(m.sequence, 77u);
  const wire::BandRowsView v = wire::decode_band_rows_view(m.payload);
  EXPECT_EQ(v.row_begin, 2u);
  EXPECT_EQ(v.row_end, 4u);
  EXPECT_EQ(v.row_work, work);
  ASSERT_EQ(v.pixel_bytes, 2 * band.row_bytes());
  EXPECT_EQ(std::memcmp(v.pixels, band.row(2), v.pixel_bytes), 0);
  ASSERT_EQ(v.aux_bytes, 2 * 8 * sizeof(KAuxTexel));
  EXPECT_EQ(std::memcmp(v.aux, band.aux_row(2), v.aux_bytes), 0);
  EXPECT_GE(v.pixels, m.payload.data());
  EXPECT_LT(v.aux, m.payload.data() + m.payload.size()) << "views into the payload, not copies";
  expect_every_prefix_refused(m.payload, [](const auto& p) { return wire::decode_band_rows_view(p); });
}

TEST(WireCodec, BandJobsOutsideTheFrameAreRefused) {
  wire::BandRequest request;
  request.job.camera.width = 64;
  request.job.camera.height = 48;
  request.job.params.row_begin = 8;
  request.job.params.row_end = 16;
  request.aux = true;
  const wire::BandRequest back = wire::decode_band_request(wire::encode_band_request(request));
  EXPECT_EQ(back.job.params.row_end, 16u);
  EXPECT_TRUE(back.aux);
  EXPECT_EQ(back.format, core::BandFormat::rgb16f);
  request.job.params.row_end = 49;
  EXPECT_NE(refusal([&] { wire::decode_band_request(wire::encode_band_request(request)); }).find("do not fit"),
            std::string::npos);
  expect_every_prefix_refused(wire::encode_band_request(back), [](const auto& p) { return wire::decode_band_request(p); });
}

TEST(WireCodec, HelloAndFailuresRoundTrip) {
  wire::Hello hello;
  hello.cohort_version = "9.9.9";
  hello.host = "node-a";
  hello.tracers = "cuda:0,cuda:1";
  hello.scene_fingerprint = 0x1234;
  hello.scene_name = "delta1";
  const wire::Hello back = wire::decode_hello(wire::encode_hello(hello));
  EXPECT_EQ(back.cohort_version, "9.9.9");
  EXPECT_EQ(back.host, "node-a");
  EXPECT_EQ(back.tracers, "cuda:0,cuda:1");
  EXPECT_EQ(back.scene_fingerprint, 0x1234u);
  EXPECT_EQ(back.scene_name, "delta1");
  expect_every_prefix_refused(wire::encode_hello(hello), [](const auto& p) { return wire::decode_hello(p); });
  const wire::BandFailure failure = wire::decode_band_failure(wire::encode_band_failure({true, "scene behind"}));
  EXPECT_TRUE(failure.needs_full_resync);
  EXPECT_EQ(failure.reason, "scene behind");
}

TEST(WireCodec, FingerprintFollowsContentNotCamera) {
  test::SceneChurn churn(21);
  churn.step(1, true);
  commit::TracerScene a = churn.master(), b = churn.master();
  EXPECT_EQ(wire::scene_fingerprint(a), wire::scene_fingerprint(b));
  b.camera.origin[0] += 10.0f;
  b.version += 3;
  EXPECT_EQ(wire::scene_fingerprint(a), wire::scene_fingerprint(b));
  ASSERT_FALSE(b.instances.empty());
  b.instances.back().object_to_world[3] += 1.0f;
  EXPECT_NE(wire::scene_fingerprint(a), wire::scene_fingerprint(b));
  EXPECT_NE(wire::scene_fingerprint(commit::TracerScene{}), 0u);
}
