// The MPI wire codec (tracers/mpi/mpi_wire.h) on its own: what it encodes decodes to the same scene
// changes, and every malformed or truncated message is refused with a reason instead of being applied.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

TEST(WireCodec, AJoinNamesItsSlotAndNothingElse) {
  const std::vector<uint8_t> join = wire::frame_message(wire::Kind::join, 0, wire::encode_join(2));
  const wire::Message m = wire::parse_message(join.data(), join.size());
  EXPECT_EQ(m.kind, wire::Kind::join);
  EXPECT_EQ(wire::decode_join(m.payload), 2u);
  std::vector<uint8_t> longer = m.payload;
  longer.push_back(0);
  EXPECT_THROW(wire::decode_join(longer), wire::WireError);
  EXPECT_THROW(wire::decode_join(std::vector<uint8_t>(m.payload.begin(), m.payload.end() - 1)), wire::WireError);
}

TEST(WireCodec, WarmCarriesTheWarmUpBandOrNone) {
  wire::Warm none;
  const std::vector<uint8_t> bare = wire::frame_message(wire::Kind::warm, 0, wire::encode_warm(none));
  const wire::Message m = wire::parse_message(bare.data(), bare.size());
  EXPECT_EQ(m.kind, wire::Kind::warm);
  EXPECT_FALSE(wire::decode_warm(m.payload).has_job);
  EXPECT_EQ(m.payload.size(), 1u);

  wire::Warm warm;
  warm.has_job = true;
  warm.request.job.camera.width = 64;
  warm.request.job.camera.height = 48;
  warm.request.job.params.row_begin = 8;
  warm.request.job.params.row_end = 40;
  warm.request.job.params.frame_index = 17;
  warm.request.format = core::BandFormat::rgb9e5;
  const wire::Warm back = wire::decode_warm(wire::encode_warm(warm));
  ASSERT_TRUE(back.has_job);
  EXPECT_EQ(back.request.job.params.row_begin, 8u);
  EXPECT_EQ(back.request.job.params.row_end, 40u);
  EXPECT_EQ(back.request.job.params.frame_index, 17u);
  EXPECT_EQ(back.request.format, core::BandFormat::rgb9e5);
  expect_every_prefix_refused(wire::encode_warm(warm), [](const auto& p) { return wire::decode_warm(p); });

  std::vector<uint8_t> bad_flag = wire::encode_warm(none);
  bad_flag[0] = 2;
  EXPECT_NE(refusal([&] { wire::decode_warm(bad_flag); }).find("job flag 2"), std::string::npos);
  std::vector<uint8_t> longer = wire::encode_warm(none);
  longer.push_back(0);
  EXPECT_NE(refusal([&] { wire::decode_warm(longer); }).find("left over"), std::string::npos);
  // The band inside is checked as any band job is, and may be neither ahead nor adopting.
  warm.request.job.params.row_end = 49;
  EXPECT_NE(refusal([&] { wire::decode_warm(wire::encode_warm(warm)); }).find("do not fit"), std::string::npos);
  warm.request.job.params.row_end = 40;
  warm.request.ahead = true;
  EXPECT_NE(refusal([&] { wire::decode_warm(wire::encode_warm(warm)); }).find("neither a job ahead"), std::string::npos);
}

TEST(WireCodec, ReadyCarriesItsTimesAndFailure) {
  wire::Ready ready;
  ready.resync_ms = 41.5;
  ready.warm_ms = 7.25;
  const std::vector<uint8_t> framed = wire::frame_message(wire::Kind::ready, 3, wire::encode_ready(ready));
  const wire::Message m = wire::parse_message(framed.data(), framed.size());
  EXPECT_EQ(m.kind, wire::Kind::ready);
  EXPECT_EQ(m.sequence, 3u);
  const wire::Ready back = wire::decode_ready(m.payload);
  EXPECT_EQ(back.resync_ms, 41.5);
  EXPECT_EQ(back.warm_ms, 7.25);
  EXPECT_TRUE(back.failure.empty());
  ready.failure = "the node's scene is behind: refused full resync";
  EXPECT_EQ(wire::decode_ready(wire::encode_ready(ready)).failure, ready.failure);
  expect_every_prefix_refused(wire::encode_ready(ready), [](const auto& p) { return wire::decode_ready(p); });
  std::vector<uint8_t> longer = wire::encode_ready(ready);
  longer.push_back(0);
  EXPECT_NE(refusal([&] { wire::decode_ready(longer); }).find("left over"), std::string::npos);
  for (double bad : {-1.0, std::nan(""), 1e12}) {
    wire::Ready odd;
    odd.warm_ms = bad;
    EXPECT_NE(refusal([&] { wire::decode_ready(wire::encode_ready(odd)); }).find("out of range"), std::string::npos) << bad;
  }
  // A kind past ready is unknown to this protocol.
  std::vector<uint8_t> unknown = framed;
  unknown[6] = uint8_t(wire::Kind::ready) + 1;
  EXPECT_NE(refusal([&] { wire::parse_message(unknown.data(), unknown.size()); }).find("unknown message kind"),
            std::string::npos);
}

TEST(WireCodec, AVersionMismatchNamesBothVersionsAndTheSlot) {
  wire::Hello hello;
  hello.cohort_version = wire::cohort_version();
  hello.host = "gpu2";
  EXPECT_EQ(wire::version_mismatch(hello, 2), "");
  hello.cohort_version = "0.0.0-test";
  const std::string why = wire::version_mismatch(hello, 2);
  EXPECT_NE(why.find("rank 0 runs Cohort " + wire::cohort_version()), std::string::npos) << why;
  EXPECT_NE(why.find("rank 2 on gpu2 runs Cohort 0.0.0-test"), std::string::npos) << why;
  hello.cohort_version = wire::cohort_version();
  hello.protocol = wire::kProtocolVersion - 1;
  EXPECT_NE(wire::version_mismatch(hello, 1).find("(protocol " + std::to_string(wire::kProtocolVersion - 1) + ")"),
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
  other_protocol[4] = uint8_t(wire::kProtocolVersion + 1);
  EXPECT_NE(refused(other_protocol).find("protocol version " + std::to_string(wire::kProtocolVersion + 1)),
            std::string::npos);
  std::vector<uint8_t> unknown_kind = good;
  unknown_kind[6] = 77;
  EXPECT_NE(refused(unknown_kind).find("unknown message kind 77"), std::string::npos);
  std::vector<uint8_t> truncated(good.begin(), good.end() - 3);
  EXPECT_NE(refused(truncated).find("announces"), std::string::npos);
  for (size_t n = 0; n < sizeof(wire::Header); ++n)
    EXPECT_NE(refused(std::vector<uint8_t>(good.begin(), good.begin() + long(n))).find("shorter than"),
              std::string::npos);
}

TEST(WireCodec, BandRowsCloseABandAndEveryFieldIsChecked) {
  wire::BandRows done;
  done.row_begin = 10;
  done.row_end = 13;
  done.width = 8;
  done.format = core::BandFormat::rgba32f;
  done.pieces = 3;
  done.aux = true;
  done.device_ms = 2.5;
  done.timing = {2.5, 2.0, 1.5, 0.25, 0.75, 0.5, 0.125, 0.375, 1.25};
  done.row_work = {3.0f, 4.0f, 5.0f};
  const std::vector<uint8_t> payload = wire::encode_band_rows(done);
  EXPECT_EQ(payload.size(), 6 * 4 + 8 + 8 + 72 + 8 + 3 * 4) << "no pixels: they went ahead as pieces";
  const wire::BandRows back = wire::decode_band_rows(payload);
  EXPECT_EQ(back.row_begin, 10u);
  EXPECT_EQ(back.row_end, 13u);
  EXPECT_EQ(back.width, 8u);
  EXPECT_EQ(back.format, core::BandFormat::rgba32f);
  EXPECT_EQ(back.pieces, 3u);
  EXPECT_TRUE(back.aux);
  EXPECT_EQ(back.device_ms, 2.5);
  EXPECT_EQ(back.timing.render_ms, 2.0);
  EXPECT_EQ(back.timing.first_piece_ms, 0.75);
  EXPECT_EQ(back.timing.commit_ms, 0.5);
  EXPECT_EQ(back.timing.commit_ahead_ms, 0.125);
  EXPECT_EQ(back.timing.idle_ms, 0.375);
  EXPECT_EQ(back.timing.ahead_ms, 1.25);
  EXPECT_EQ(back.adopted, 0u);
  EXPECT_EQ(back.row_work, done.row_work);
  expect_every_prefix_refused(payload, [](const auto& p) { return wire::decode_band_rows(p); });

  auto changed = [&](auto change) {
    wire::BandRows bad = done;
    change(bad);
    return refusal([&] { wire::decode_band_rows(wire::encode_band_rows(bad)); });
  };
  EXPECT_NE(changed([](wire::BandRows& b) { b.pieces = 4; }).find("4 pieces for a band of 3 rows"), std::string::npos);
  EXPECT_NE(changed([](wire::BandRows& b) { b.pieces = 0; }).find("0 pieces"), std::string::npos);
  EXPECT_NE(changed([](wire::BandRows& b) { b.row_work.pop_back(); }).find("2 row work values for 3 rows"),
            std::string::npos);
  EXPECT_NE(changed([](wire::BandRows& b) { b.row_end = 9; }).find("end before they begin"), std::string::npos);
  EXPECT_NE(changed([](wire::BandRows& b) { b.width = 0; }).find("width 0"), std::string::npos);
  EXPECT_NE(changed([](wire::BandRows& b) { b.timing.send_ms = std::nan(""); }).find("not a duration"),
            std::string::npos);
  EXPECT_NE(changed([](wire::BandRows& b) { b.device_ms = -1.0; }).find("not a duration"), std::string::npos);
  EXPECT_NE(changed([](wire::BandRows& b) { b.timing.commit_ahead_ms = -0.5; }).find("not a duration"),
            std::string::npos);
  EXPECT_NE(changed([](wire::BandRows& b) { b.timing.ahead_ms = -0.5; }).find("not a duration"), std::string::npos);
  // A band that adopted a job ahead sent only the runs of rows beyond it: none to two pieces.
  wire::BandRows adopted = done;
  adopted.adopted = 77;
  for (uint32_t pieces : {0u, 1u, 2u}) {
    adopted.pieces = pieces;
    EXPECT_EQ(wire::decode_band_rows(wire::encode_band_rows(adopted)).pieces, pieces);
  }
  EXPECT_EQ(wire::decode_band_rows(wire::encode_band_rows(adopted)).adopted, 77u);
  adopted.pieces = 3;
  EXPECT_NE(refusal([&] { wire::decode_band_rows(wire::encode_band_rows(adopted)); }).find("3 pieces beyond the adopted rows"),
            std::string::npos);
  std::vector<uint8_t> bad_aux = payload;
  bad_aux[20] = 2;  // the aux flag
  EXPECT_NE(refusal([&] { wire::decode_band_rows(bad_aux); }).find("aux flag 2"), std::string::npos);
  std::vector<uint8_t> bad_format = payload;
  bad_format[12] = 9;
  EXPECT_NE(refusal([&] { wire::decode_band_rows(bad_format); }).find("unknown band format 9"), std::string::npos);
  std::vector<uint8_t> longer = payload;
  longer.push_back(0);
  EXPECT_NE(refusal([&] { wire::decode_band_rows(longer); }).find("left over"), std::string::npos);
}

TEST(WireCodec, PiecesCoverTheBandInOrderAndTheirTagsNameJobPieceAndPlane) {
  for (uint32_t rows : {1u, 3u, 4u, 7u, 540u, 1080u}) {
    for (uint32_t wanted : {1u, 2u, 4u, 5u, 32u, 100u}) {
      const uint32_t pieces = wire::band_pieces(rows, wanted);
      EXPECT_GE(pieces, 1u);
      EXPECT_LE(pieces, std::min({wanted, rows, wire::kMaxPieces}));
      uint32_t next = 100;
      for (uint32_t i = 0; i < pieces; ++i) {
        const wire::RowRange r = wire::piece_rows(100, 100 + rows, pieces, i);
        EXPECT_EQ(r.begin, next) << rows << " rows in " << pieces;
        EXPECT_GT(r.end, r.begin) << "no piece is empty";
        EXPECT_LE(r.end - r.begin, rows / pieces + 1) << "as even as whole rows allow";
        next = r.end;
      }
      EXPECT_EQ(next, 100 + rows);
    }
  }
  EXPECT_EQ(wire::band_pieces(0, 4), 1u) << "an empty band still closes with one (empty) piece";
  EXPECT_EQ(wire::piece_bytes(3, 8, core::BandFormat::rgb16f, wire::Plane::colour), 3u * 8u * 6u);
  EXPECT_EQ(wire::piece_bytes(3, 8, core::BandFormat::rgb9e5, wire::Plane::colour), 3u * 8u * 4u);
  EXPECT_EQ(wire::piece_bytes(3, 8, core::BandFormat::rgba32f, wire::Plane::aux), 3u * 8u * sizeof(KAuxTexel));

  std::vector<bool> used(32768, false);
  wire::PieceTag decoded;
  EXPECT_FALSE(wire::decode_piece_tag(wire::kControlTag, decoded)) << "the control tag is no piece's";
  for (uint64_t job : {uint64_t(1), uint64_t(63), uint64_t(64), uint64_t(1) << 40})
    for (uint32_t piece = 0; piece < wire::kMaxPieces; ++piece)
      for (wire::Plane plane : {wire::Plane::colour, wire::Plane::aux}) {
        const int tag = wire::piece_tag(job, piece, plane);
        ASSERT_GT(tag, wire::kControlTag);
        ASSERT_LE(tag, 32767) << "within the tags every MPI library offers";
        ASSERT_TRUE(wire::decode_piece_tag(tag, decoded));
        EXPECT_TRUE(decoded.of_job(job));
        EXPECT_FALSE(decoded.of_job(job + 1));
        EXPECT_EQ(decoded.piece, piece);
        EXPECT_EQ(decoded.plane, plane);
        if (job < wire::kPieceJobSlots) {
          EXPECT_FALSE(used[size_t(tag)]) << "tag " << tag << " twice";
          used[size_t(tag)] = true;
        }
      }
  EXPECT_FALSE(wire::decode_piece_tag(wire::kPieceTagBase - 1, decoded));
  EXPECT_FALSE(wire::decode_piece_tag(wire::kPieceTagBase + int(wire::kPieceJobSlots * wire::kMaxPieces * 2), decoded));
}

TEST(WireCodec, BandJobsOutsideTheFrameAreRefused) {
  wire::BandRequest request;
  request.job.camera.width = 64;
  request.job.camera.height = 48;
  request.job.params.row_begin = 8;
  request.job.params.row_end = 16;
  request.aux = true;
  request.pieces = 4;
  const wire::BandRequest back = wire::decode_band_request(wire::encode_band_request(request));
  EXPECT_EQ(back.job.params.row_end, 16u);
  EXPECT_TRUE(back.aux);
  EXPECT_EQ(back.pieces, 4u);
  request.pieces = 9;
  EXPECT_NE(refusal([&] { wire::decode_band_request(wire::encode_band_request(request)); }).find("9 pieces for a band of 8 rows"),
            std::string::npos);
  request.pieces = 0;
  EXPECT_NE(refusal([&] { wire::decode_band_request(wire::encode_band_request(request)); }).find("0 pieces"),
            std::string::npos);
  request.pieces = 4;
  EXPECT_EQ(back.format, core::BandFormat::rgb16f);
  request.format = core::BandFormat::rgb9e5;
  EXPECT_EQ(wire::decode_band_request(wire::encode_band_request(request)).format, core::BandFormat::rgb9e5);
  request.format = core::BandFormat::rgb16f;
  request.job.params.row_end = 49;
  EXPECT_NE(refusal([&] { wire::decode_band_request(wire::encode_band_request(request)); }).find("do not fit"),
            std::string::npos);
  expect_every_prefix_refused(wire::encode_band_request(back), [](const auto& p) { return wire::decode_band_request(p); });
  EXPECT_EQ(wire::encode_band_request(back).size(), 4 + sizeof(core::BandJob) + 4 * 4 + 8);

  // Jobs ahead: a job ahead, and a band that adopts one with its rows beyond in 0 to 2 pieces.
  request.job.params.row_end = 16;
  request.ahead = true;
  EXPECT_TRUE(wire::decode_band_request(wire::encode_band_request(request)).ahead);
  request.adopt = 5;
  EXPECT_NE(refusal([&] { wire::decode_band_request(wire::encode_band_request(request)); }).find("cannot adopt"),
            std::string::npos);
  request.ahead = false;
  for (uint32_t pieces : {0u, 2u}) {
    request.pieces = pieces;
    const wire::BandRequest adopting = wire::decode_band_request(wire::encode_band_request(request));
    EXPECT_EQ(adopting.adopt, 5u);
    EXPECT_EQ(adopting.pieces, pieces);
  }
  request.pieces = 3;
  EXPECT_NE(refusal([&] { wire::decode_band_request(wire::encode_band_request(request)); }).find("3 pieces beyond"),
            std::string::npos);
  std::vector<uint8_t> bad_ahead = wire::encode_band_request(back);
  bad_ahead[4 + sizeof(core::BandJob) + 12] = 2;  // the ahead flag
  EXPECT_NE(refusal([&] { wire::decode_band_request(bad_ahead); }).find("ahead flag 2"), std::string::npos);
}

TEST(WireCodec, RowsBeyondAJobAheadAreTheBandsRowsItDidNotCover) {
  using R = wire::RowRange;
  auto beyond = [](R ahead, R band) {
    std::vector<std::pair<uint32_t, uint32_t>> out;
    for (const R& r : wire::rows_beyond(ahead, band)) out.emplace_back(r.begin, r.end);
    return out;
  };
  using V = std::vector<std::pair<uint32_t, uint32_t>>;
  EXPECT_EQ(beyond({10, 20}, {10, 20}), V{}) << "the same rows: nothing left to render";
  EXPECT_EQ(beyond({10, 20}, {12, 18}), V{}) << "the band shrank: nothing left";
  EXPECT_EQ(beyond({10, 20}, {8, 20}), (V{{8, 10}}));
  EXPECT_EQ(beyond({10, 20}, {10, 24}), (V{{20, 24}}));
  EXPECT_EQ(beyond({10, 20}, {6, 26}), (V{{6, 10}, {20, 26}})) << "below and above";
  EXPECT_EQ(beyond({10, 20}, {14, 28}), (V{{20, 28}}));
  EXPECT_TRUE(wire::rows_overlap({10, 20}, {19, 30}));
  EXPECT_FALSE(wire::rows_overlap({10, 20}, {20, 30}));
  EXPECT_FALSE(wire::rows_overlap({10, 10}, {0, 30})) << "an empty range overlaps nothing";
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
