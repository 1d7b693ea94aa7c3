#include "cohort/tracers/mpi_node.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <csignal>
#include <cstring>
#include <exception>
#include <fstream>
#include <memory>
#include <functional>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "cohort/balance/bands.h"
#include "cohort/core/band_buffer.h"
#include "cohort/tracers/mpi_join_socket.h"
#include "cohort/tracers/mpi_link.h"
#include "cohort/tracers/mpi_wire.h"

namespace cohort::tracers {

namespace {

constexpr int kRank0 = 0;

double ms_since(MpiClock::time_point start) {
  return std::chrono::duration<double, std::milli>(MpiClock::now() - start).count();
}

std::string host_name() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return "unknown host";
  return name;
}

void send(MpiSession& mpi, wire::Kind kind, uint64_t sequence, const std::vector<uint8_t>& payload) {
  mpi.send(kRank0, wire::frame_message(kind, sequence, payload));
}

// The closing message of the band `request` asked for: its rows, their format and pieces as the request
// had them (the caller adds the work, timing and, for a band that adopts a job ahead, its id).
wire::BandRows band_rows_of(const wire::BandRequest& request) {
  wire::BandRows done;
  done.row_begin = request.job.params.row_begin;
  done.row_end = request.job.params.row_end;
  done.width = request.job.camera.width;
  done.format = request.format;
  done.pieces = request.pieces;
  done.aux = request.aux;
  return done;
}

// The next well-formed message from rank 0 (a malformed one is logged, skipped, and the wait starts
// again); nothing when rank 0 stays silent for `timeout`.
std::optional<wire::Message> receive_from_rank0(MpiSession& mpi, std::chrono::seconds timeout) {
  for (;;) {
    std::optional<std::vector<uint8_t>> bytes = mpi.receive(kRank0, MpiClock::now() + timeout);
    if (!bytes) return std::nullopt;
    try {
      return wire::parse_message(bytes->data(), bytes->size());
    } catch (const wire::WireError& e) {
      spdlog::warn("node {}: refused a message: {}", mpi.rank(), e.what());
    }
  }
}

class Node {
 public:
  Node(std::vector<std::unique_ptr<core::Tracer>> tracers, const NodeOptions& options)
      : tracers_(std::move(tracers)), options_(options), rows_per_ms_(tracers_.size(), 1.0) {}

  int serve(MpiSession& mpi) {
    for (;;) {
      const auto wait_start = MpiClock::now();
      std::optional<wire::Message> received = receive_from_rank0(mpi, options_.idle_timeout);
      idle_ms_ += ms_since(wait_start);  // nothing to do meanwhile: waiting for rank 0
      if (!received) {
        spdlog::error("node {}: rank 0 was silent for {} s; leaving", mpi.rank(), options_.idle_timeout.count());
        return 1;
      }
      wire::Message& m = *received;
      switch (m.kind) {
        case wire::Kind::commit: timed_commit(mpi, [&] { apply_commit(m); }); break;
        case wire::Kind::full_local: timed_commit(mpi, [&] { apply_full_local(m); }); break;
        case wire::Kind::band_job: render(mpi, m); break;
        case wire::Kind::warm: warm_up(mpi, m); break;
        case wire::Kind::shutdown:
          spdlog::info("node {}: shutdown from rank 0 after {} band(s), {} of them on rows rendered ahead; {:.1f} KiB "
                       "of colour rows a band as {} ({} bytes a pixel)", mpi.rank(), bands_, adopted_,
                       bands_ > 0 ? double(colour_bytes_sent_) / 1024.0 / double(bands_) : 0.0,
                       core::to_string(last_format_), core::bytes_per_pixel(last_format_));
          mpi.flush_sends(kRank0, MpiClock::now() + std::chrono::seconds(2));
          return 0;
        default:
          spdlog::warn("node {}: ignored an unexpected {} message", mpi.rank(), wire::to_string(m.kind));
      }
    }
  }

 private:
  // A commit comes after the job of the band it follows (rank 0 sends the commits it takes while a band
  // renders right behind that band's job: MpiTracer::apply), so it is applied here, once that band is
  // rendered and never under it, while rank 0 still receives the band and waits for the frame. The
  // band's last pieces may still be on their way: they keep moving meanwhile (a library may move a large
  // message only inside MPI calls).
  template <class Apply> void timed_commit(MpiSession& mpi, Apply&& apply) {
    const auto start = MpiClock::now();
    if (mpi.progress_sends() > 0)
      run_while_sending(mpi, apply);
    else
      apply();
    const double ms = ms_since(start);
    // With the next job already waiting, the commit was in the round trip's way (at most by its time);
    // otherwise it was hidden.
    (mpi.control_waiting(kRank0) ? commit_ms_ : commit_ahead_ms_) += ms;
  }

  // A refused or failed commit leaves the scene behind rank 0's: every band fails, asking for a full
  // resync, until one arrives.
  void apply_commit(const wire::Message& m) {
    const auto start = MpiClock::now();
    commit::CommitBuffer commit;
    try {
      commit = wire::decode_commit(m.payload);
    } catch (const wire::WireError& e) {
      diverge(fmt::format("refused commit of frame {}: {}", m.sequence, e.what()));
      return;
    }
    apply(commit);
    if (commit.is_full_resync()) resync_ms_ = ms_since(start);
  }

  void apply_full_local(const wire::Message& m) {
    const auto start = MpiClock::now();
    if (!options_.scene) {
      diverge("rank 0 sent a full resync to the node's own scene, but it loaded none");
      return;
    }
    commit::CommitBuffer full;
    try {
      full = wire::decode_full_local(m.payload, options_.scene);
    } catch (const wire::WireError& e) {
      diverge(fmt::format("refused full resync of frame {}: {}", m.sequence, e.what()));
      return;
    }
    apply(full);
    resync_ms_ = ms_since(start);
  }

  // A node that joined a running session: its full resync came right before this (and was applied on
  // arrival, as every commit is). It renders the warm-up band, when rank 0 sent one, for nothing (its
  // kernels load, its buffers are made, the band buffer its first band will use is page-locked), then
  // says it is ready, so that its first real band is an ordinary one (docs/cluster.md, "Joining a running
  // session"). A scene that is behind says so instead: rank 0 sends another full resync.
  void warm_up(MpiSession& mpi, const wire::Message& m) {
    wire::Ready ready;
    ready.resync_ms = resync_ms_;
    wire::Warm warm;
    try {
      warm = wire::decode_warm(m.payload);
    } catch (const wire::WireError& e) {
      spdlog::warn("node {}: refused a warm message: {}", mpi.rank(), e.what());
      warm.has_job = false;
    }
    if (diverged_) {
      ready.failure = "the node's scene is behind: " + divergence_;
    } else if (warm.has_job) {
      const auto start = MpiClock::now();
      double send_ms = 0.0;
      const size_t slot = take_slot(mpi, send_ms);
      next_slot_ = slot;  // the first real band renders into the buffer warmed here
      core::BandBuffer& target = slots_[slot].buffer;
      core::BandJob job = warm.request.job;
      job.keep_on_device = -1;
      target.resize(int(job.camera.width), int(job.camera.height), warm.request.format);
      target.enable_aux(warm.request.aux);
      try {
        render_while_sending(mpi, job, target, {int(job.params.row_begin), int(job.params.row_end)}, [](size_t) {},
                             nullptr);
      } catch (const std::exception& e) {
        ready.failure = std::string("the warm-up band failed: ") + e.what();
      }
      ready.warm_ms = ms_since(start);
    }
    spdlog::info("node {}: {} (full resync applied in {:.1f} ms, warm-up band {:.1f} ms)", mpi.rank(),
                 ready.failure.empty() ? "ready" : "not ready: " + ready.failure, ready.resync_ms, ready.warm_ms);
    send(mpi, wire::Kind::ready, m.sequence, wire::encode_ready(ready));
    idle_ms_ = 0.0;  // warming is not waiting for rank 0
  }

  void apply(const commit::CommitBuffer& commit) {
    if (diverged_ && !commit.is_full_resync()) return;  // records on top of a stale scene would be garbage
    if (commit.is_full_resync() && options_.resync_delay_ms > 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(options_.resync_delay_ms));
    try {
      for (auto& tracer : tracers_) tracer->apply(commit);
      diverged_ = false;
    } catch (const std::exception& e) {
      diverge(fmt::format("applying the commit of frame {} failed: {}", commit.frame(), e.what()));
    }
  }

  void diverge(std::string why) {
    spdlog::warn("node: {}; waiting for a full resync", why);
    if (!diverged_) divergence_ = std::move(why);
    diverged_ = true;
  }

  struct Rendered {
    std::vector<float> row_work;
    double tracer_ms = 0.0;  // what the tracers measured themselves (summed over pieces; the slowest part's)
    double mpi_ms = 0.0;     // in MPI calls moving the pieces sent, meanwhile
  };

  // A band's buffer: the node renders into one while the pieces of the band before may still be leaving
  // the other (a job ahead is rendered while rank 0 has not yet taken the band before it). The token names
  // the buffer's sends (MpiSession::flush_group) and stays with them if the buffer is retired.
  struct BandSlot {
    core::BandBuffer buffer;
    std::unique_ptr<char> token = std::make_unique<char>();
  };

  // The next buffer, its last band's pieces gone (they have, unless rank 0 stopped reading: then a fresh
  // buffer takes its place and the old one stays with its sends).
  size_t take_slot(MpiSession& mpi, double& send_ms) {
    const size_t index = next_slot_;
    next_slot_ ^= 1;
    const auto send_start = MpiClock::now();
    if (!mpi.flush_group(slots_[index].token.get(), MpiClock::now() + std::chrono::seconds(2))) {
      spdlog::warn("node {}: a band's rows have not left after 2 s; rendering into a new buffer", mpi.rank());
      retired_.push_back(std::move(slots_[index]));
      slots_[index] = BandSlot();
    }
    send_ms += ms_since(send_start);
    return index;
  }

  // What a job ahead left for the band that adopts it.
  struct Ahead {
    uint64_t id = 0;
    wire::BandRequest request;
    size_t slot = 0;
    wire::NodeTiming timing;
    std::vector<float> row_work;
    MpiClock::time_point start{};
    MpiClock::time_point next_seen{};  // when a message from rank 0 (its job, normally) was first waiting
  };

  void render(MpiSession& mpi, const wire::Message& m) {
    const double idle = idle_ms_;
    idle_ms_ = 0.0;
    wire::BandRequest request;
    try {
      request = wire::decode_band_request(m.payload);
    } catch (const wire::WireError& e) {
      spdlog::warn("node {}: refused a band job: {}", mpi.rank(), e.what());
      send(mpi, wire::Kind::band_failed, m.sequence, wire::encode_band_failure({false, e.what()}));
      return;
    }
    if (request.adopt != 0) {
      adopt(mpi, m.sequence, request, idle);
      return;
    }
    ahead_.reset();  // whatever was rendered ahead and not adopted is dropped
    if (diverged_) {
      send(mpi, wire::Kind::band_failed, m.sequence,
           wire::encode_band_failure({true, "the node's scene is behind: " + divergence_}));
      return;
    }
    const KFrameParams& p = request.job.params;
    // The test faults strike once the band before has left (a job ahead of that frame comes while rank 0
    // still receives it), so that they hit that frame, not the one before.
    if (int(p.frame_index) == options_.die_frame) {
      mpi.flush_sends(kRank0, MpiClock::now() + std::chrono::seconds(2));
      spdlog::warn("node {}: killing itself before frame {} (--die-frame)", mpi.rank(), p.frame_index);
      std::raise(SIGKILL);
    }
    if (int(p.frame_index) == options_.stall_frame && !stalled_) {
      mpi.flush_sends(kRank0, MpiClock::now() + std::chrono::seconds(2));
      stalled_ = true;
      spdlog::warn("node {}: stalling {} ms before frame {} (--stall-frame)", mpi.rank(), options_.stall_ms,
                   p.frame_index);
      std::this_thread::sleep_for(std::chrono::milliseconds(options_.stall_ms));
    }
    const auto start = MpiClock::now();
    // A job ahead: the first message from rank 0 that waits meanwhile is, normally, the job that adopts it.
    MpiClock::time_point next_seen{};
    const std::function<void()> watch = [&] {
      if (next_seen == MpiClock::time_point{} && mpi.control_waiting(kRank0)) next_seen = MpiClock::now();
    };
    // A slow node's render, counted in its time.
    if (options_.band_delay_ms > 0)
      run_while_sending(mpi, [&] { std::this_thread::sleep_for(std::chrono::milliseconds(options_.band_delay_ms)); },
                        request.ahead ? watch : nullptr);
    wire::NodeTiming timing;
    timing.commit_ms = commit_ms_;
    timing.commit_ahead_ms = commit_ahead_ms_;
    timing.idle_ms = idle;
    commit_ms_ = commit_ahead_ms_ = 0.0;
    const size_t slot = take_slot(mpi, timing.send_ms);
    core::BandBuffer& target = slots_[slot].buffer;
    target.resize(int(request.job.camera.width), int(request.job.camera.height), request.format);
    target.enable_aux(request.aux);
    // The band in pieces: each goes out, straight from its buffer (page-locked by a CUDA tracer, which
    // downloads into it), as soon as it is rendered, and travels while the next renders.
    std::vector<wire::RowRange> pieces;
    for (uint32_t i = 0; i < request.pieces; ++i) pieces.push_back(wire::piece_rows(p.row_begin, p.row_end, request.pieces, i));
    Rendered rendered;
    try {
      rendered = render_pieces(mpi, request, m.sequence, slot, pieces, start, timing, request.ahead ? watch : nullptr);
    } catch (const std::exception& e) {
      // Pieces already sent are this job's: rank 0 takes them, then this failure.
      send(mpi, wire::Kind::band_failed, m.sequence, wire::encode_band_failure({false, e.what()}));
      return;
    }
    wire::BandRows done = band_rows_of(request);
    done.row_work = rendered.row_work;
    timing.total_ms = ms_since(start);
    done.device_ms = timing.total_ms;
    done.timing = timing;
    send(mpi, wire::Kind::band_rows, m.sequence, wire::encode_band_rows(done));
    ++bands_;
    if (request.ahead) ahead_ = Ahead{m.sequence, request, slot, timing, std::move(rendered.row_work), start, next_seen};
  }

  // The frame's job for the rows a job ahead rendered: its rows that the job ahead covered are taken as
  // they are (their pieces went to rank 0 under the job ahead's id), the rest rendered now, in the same
  // buffer, one piece per run of rows.
  void adopt(MpiSession& mpi, uint64_t sequence, const wire::BandRequest& request, double idle) {
    const auto taken = MpiClock::now();
    auto fail = [&](const std::string& why) {
      spdlog::warn("node {}: {}", mpi.rank(), why);
      send(mpi, wire::Kind::band_failed, sequence, wire::encode_band_failure({false, why}));
      ahead_.reset();
    };
    if (!ahead_ || ahead_->id != request.adopt) {
      fail(fmt::format("band {} adopts the job ahead {}, which this node did not render", sequence, request.adopt));
      return;
    }
    if (diverged_) {  // a commit after the job ahead was refused: rank 0 would not have adopted it
      send(mpi, wire::Kind::band_failed, sequence,
           wire::encode_band_failure({true, "the node's scene is behind: " + divergence_}));
      ahead_.reset();
      return;
    }
    const Ahead& a = *ahead_;
    const KFrameParams& p = request.job.params;
    KFrameParams same_rows = request.job.params;
    same_rows.row_begin = a.request.job.params.row_begin;
    same_rows.row_end = a.request.job.params.row_end;
    if (std::memcmp(&same_rows, &a.request.job.params, sizeof same_rows) != 0 ||
        std::memcmp(&request.job.camera, &a.request.job.camera, sizeof request.job.camera) != 0 ||
        std::memcmp(&request.job.previous_camera, &a.request.job.previous_camera, sizeof request.job.camera) != 0 ||
        request.format != a.request.format || request.aux != a.request.aux) {
      fail(fmt::format("band {} adopts the job ahead {}, which rendered another frame or format", sequence, a.id));
      return;
    }
    const wire::RowRange ahead_rows{a.request.job.params.row_begin, a.request.job.params.row_end};
    const wire::RowRange band_rows{p.row_begin, p.row_end};
    const std::vector<wire::RowRange> beyond = wire::rows_beyond(ahead_rows, band_rows);
    if (!wire::rows_overlap(ahead_rows, band_rows) || request.pieces != beyond.size()) {
      fail(fmt::format("band {} of rows [{}, {}) in {} piece(s) cannot adopt the job ahead of rows [{}, {})", sequence,
                       p.row_begin, p.row_end, request.pieces, ahead_rows.begin, ahead_rows.end));
      return;
    }
    wire::NodeTiming timing = a.timing;
    timing.idle_ms += idle;
    timing.commit_ms += commit_ms_;
    timing.commit_ahead_ms += commit_ahead_ms_;
    commit_ms_ = commit_ahead_ms_ = 0.0;
    // Rendered before its job came: up to the moment it was seen waiting, else all of the job ahead.
    timing.ahead_ms = a.next_seen != MpiClock::time_point{}
                          ? std::chrono::duration<double, std::milli>(a.next_seen - a.start).count()
                          : a.timing.total_ms;
    wire::NodeTiming beyond_timing;
    Rendered rendered;
    try {
      rendered = render_pieces(mpi, request, sequence, a.slot, beyond, taken, beyond_timing, nullptr);
    } catch (const std::exception& e) {
      fail(e.what());
      return;
    }
    timing.render_ms += beyond_timing.render_ms;
    timing.device_ms += beyond_timing.device_ms;
    timing.send_ms += beyond_timing.send_ms;
    timing.total_ms += ms_since(taken);
    // The band's row work: the job ahead's where it covered the band, the rows beyond's elsewhere.
    std::vector<float> work;
    if (a.row_work.size() == ahead_rows.end - ahead_rows.begin && rendered.row_work.size() == beyond_rows(beyond)) {
      size_t next_beyond = 0;
      for (uint32_t y = band_rows.begin; y < band_rows.end; ++y)
        work.push_back(y >= ahead_rows.begin && y < ahead_rows.end ? a.row_work[y - ahead_rows.begin]
                                                                   : rendered.row_work[next_beyond++]);
    }
    wire::BandRows done = band_rows_of(request);
    done.adopted = a.id;
    done.row_work = std::move(work);
    done.device_ms = timing.total_ms;
    done.timing = timing;
    ahead_.reset();
    send(mpi, wire::Kind::band_rows, sequence, wire::encode_band_rows(done));
    ++bands_;
    ++adopted_;
  }

  static size_t beyond_rows(const std::vector<wire::RowRange>& ranges) {
    size_t rows = 0;
    for (const wire::RowRange& r : ranges) rows += r.end - r.begin;
    return rows;
  }

  // Renders `pieces` (runs of rows, each sent as soon as it is in the slot's buffer, on job `sequence`'s
  // tags) and adds where the time went to `timing`. Consecutive pieces render in one call (a GPU
  // downloads each while the next renders); separate runs one after the other.
  Rendered render_pieces(MpiSession& mpi, const wire::BandRequest& request, uint64_t sequence, size_t slot,
                         const std::vector<wire::RowRange>& pieces, MpiClock::time_point start,
                         wire::NodeTiming& timing, const std::function<void()>& watch) {
    core::BandBuffer& target = slots_[slot].buffer;
    const void* group = slots_[slot].token.get();
    const uint32_t width = request.job.camera.width;
    const KFrameParams& p = request.job.params;
    Rendered total;
    bool complete_work = true;
    const auto render_start = MpiClock::now();
    for (size_t first = 0; first < pieces.size();) {
      size_t last = first + 1;
      while (last < pieces.size() && pieces[last].begin == pieces[last - 1].end) ++last;
      std::vector<int> cuts;
      for (size_t i = first; i < last; ++i) cuts.push_back(int(pieces[i].begin));
      cuts.push_back(int(pieces[last - 1].end));
      core::BandJob run = request.job;
      run.params.row_begin = pieces[first].begin;
      run.params.row_end = pieces[last - 1].end;
      // Called on the rendering thread as each piece lands in the buffer.
      auto post_piece = [&, first](size_t local) {
        const size_t i = first + local;
        const auto post_start = MpiClock::now();
        if (i == 0) timing.first_piece_ms = ms_since(start);
        const uint32_t count = pieces[i].end - pieces[i].begin;
        uint64_t colour_bytes = wire::piece_bytes(count, width, request.format, wire::Plane::colour);
        if (i == 0 && int(p.frame_index) == options_.short_piece_frame && colour_bytes > 0 && !short_piece_sent_) {
          short_piece_sent_ = true;
          spdlog::warn("node {}: sending piece 0 of frame {} a byte short (--short-piece-frame)", mpi.rank(),
                       p.frame_index);
          --colour_bytes;
        }
        mpi.send_in_place(kRank0, wire::piece_tag(sequence, uint32_t(i), wire::Plane::colour),
                          target.row(int(pieces[i].begin)), colour_bytes, group);
        colour_bytes_sent_ += colour_bytes;
        last_format_ = request.format;
        if (request.aux)
          mpi.send_in_place(kRank0, wire::piece_tag(sequence, uint32_t(i), wire::Plane::aux),
                            target.aux_row(int(pieces[i].begin)),
                            wire::piece_bytes(count, width, request.format, wire::Plane::aux), group);
        timing.send_ms += ms_since(post_start);
      };
      Rendered part = render_while_sending(mpi, run, target, cuts, post_piece, watch);
      total.tracer_ms += part.tracer_ms;
      total.mpi_ms += part.mpi_ms;
      complete_work = complete_work && part.row_work.size() == size_t(run.params.row_end - run.params.row_begin);
      if (complete_work) total.row_work.insert(total.row_work.end(), part.row_work.begin(), part.row_work.end());
      first = last;
    }
    if (!complete_work) total.row_work.clear();
    timing.render_ms += ms_since(render_start);
    timing.send_ms += total.mpi_ms;
    timing.device_ms += total.tracer_ms;
    return total;
  }

  // Renders the band's pieces on a thread of their own, `post_piece(i)` sending each as it lands, while
  // this thread keeps the sends going: a library may move a large message only inside MPI calls (with
  // naps, so as not to take a core from a CPU tracer). One tracer renders the pieces itself (a GPU
  // downloads each while the next renders); several split each piece by their speed.
  Rendered render_while_sending(MpiSession& mpi, const core::BandJob& job, core::BandBuffer& target,
                                const std::vector<int>& cuts, const std::function<void(size_t)>& post_piece,
                                const std::function<void()>& watch) {
    Rendered rendered;
    rendered.mpi_ms = run_while_sending(mpi, [&] {
      if (options_.row_delay_ms <= 0.0 && tracers_.size() == 1) {
        core::BandResult result = tracers_.front()->render_band_in_pieces(job, target, cuts, post_piece);
        rendered.tracer_ms = result.device_ms;
        rendered.row_work = std::move(result.row_work);
        return;
      }
      bool complete_work = true;
      for (size_t i = 0; i + 1 < cuts.size(); ++i) {
        // A slower node, in proportion to its rows (tests, and a GPU's timing on a CPU node): each piece is
        // that much later, so the pieces still leave one by one while the band renders, as a GPU's do.
        if (options_.row_delay_ms > 0.0)
          std::this_thread::sleep_for(
              std::chrono::duration<double, std::milli>(options_.row_delay_ms * double(cuts[i + 1] - cuts[i])));
        core::BandJob piece = job;
        piece.params.row_begin = uint32_t(cuts[i]);
        piece.params.row_end = uint32_t(cuts[i + 1]);
        double ms = 0.0;
        std::vector<float> work = render_split(piece, target, ms);
        rendered.tracer_ms += ms;
        complete_work = complete_work && work.size() == size_t(cuts[i + 1] - cuts[i]);
        if (complete_work) rendered.row_work.insert(rendered.row_work.end(), work.begin(), work.end());
        post_piece(i);
      }
      if (!complete_work) rendered.row_work.clear();
    }, watch);
    return rendered;
  }

  // Runs `work` on a thread of its own while this thread keeps the sends going (with naps, so as not to
  // take a core from a CPU tracer); rethrows what it threw. Returns the time spent in MPI calls.
  // The work's end wakes this thread at once (band_rows follows it), not at its next nap's end.
  // `watch`, when given, runs between the polls (without the session's lock).
  static double run_while_sending(MpiSession& mpi, const std::function<void()>& work,
                                  const std::function<void()>& watch = {}) {
    std::mutex mutex;
    std::condition_variable ended;
    bool finished = false;
    std::exception_ptr error;
    std::thread worker([&] {
      try {
        work();
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard lock(mutex);
      finished = true;
      ended.notify_one();
    });
    double mpi_ms = 0.0;
    std::unique_lock lock(mutex);
    while (!finished) {
      lock.unlock();
      const auto call = MpiClock::now();
      const bool sending = mpi.progress_sends() > 0;
      if (watch) watch();
      mpi_ms += ms_since(call);
      lock.lock();
      ended.wait_for(lock, std::chrono::microseconds(sending ? 30 : 60), [&] { return finished; });
    }
    lock.unlock();
    worker.join();
    if (error) std::rethrow_exception(error);
    return mpi_ms;
  }

  // The band split among the node's tracers by their last speed, rendered in parallel; a tracer that
  // fails has its rows re-rendered by one that did not. Returns the per-row work when every part
  // reported it.
  std::vector<float> render_split(const core::BandJob& job, core::BandBuffer& target, double& tracer_ms) {
    const uint32_t begin = job.params.row_begin, end = job.params.row_end, rows = end - begin;
    const size_t n = tracers_.size();
    // Shares in proportion to speed (the balancer module's Perfect division, in its 4-row units): the
    // band's size changes every frame with rank 0's balancing, so speeds, not bands, are what carry over.
    std::vector<uint32_t> cuts(n + 1, begin);
    const std::vector<balance::Band> parts = balance::bands_from_shares(int(rows), rows_per_ms_);
    for (size_t i = 0; i < n; ++i) cuts[i + 1] = begin + uint32_t(parts[i].end);
    cuts[n] = end;
    std::vector<core::BandResult> results(n);
    std::vector<std::string> errors(n);
    std::vector<double> ms(n, 0.0);
    auto render_part = [&](size_t i, uint32_t from, uint32_t to) {
      if (from >= to) return;
      core::BandJob part = job;
      part.keep_on_device = -1;  // the node sends rows, whatever rank 0 asked
      part.params.row_begin = from;
      part.params.row_end = to;
      const auto start = MpiClock::now();
      try {
        results[i] = tracers_[i]->render_band(part, target);
        errors[i].clear();
      } catch (const std::exception& e) {
        errors[i] = tracers_[i]->name() + ": " + e.what();
      }
      ms[i] = std::chrono::duration<double, std::milli>(MpiClock::now() - start).count();
    };
    if (n == 1) {
      render_part(0, begin, end);
    } else {
      std::vector<std::thread> threads;
      for (size_t i = 0; i < n; ++i) threads.emplace_back(render_part, i, cuts[i], cuts[i + 1]);
      for (auto& t : threads) t.join();
    }
    for (size_t i = 0; i < n; ++i) {
      if (!errors[i].empty() || cuts[i] >= cuts[i + 1]) continue;
      const double speed = std::max(double(cuts[i + 1] - cuts[i]) / std::max(ms[i], 1e-3), 1e-3);
      rows_per_ms_[i] = 0.5 * rows_per_ms_[i] + 0.5 * speed;  // smoothed like Perfect Smooth's alpha 0.5
    }
    tracer_ms = 0.0;
    for (size_t i = 0; i < n; ++i) tracer_ms = std::max(tracer_ms, results[i].device_ms);
    bool complete_work = true;
    for (size_t i = 0; i < n; ++i) {
      if (errors[i].empty()) {
        complete_work = complete_work && results[i].row_work.size() == cuts[i + 1] - cuts[i];
        continue;
      }
      spdlog::warn("node: {}; re-rendering its rows on the node's other tracers", errors[i]);
      rows_per_ms_[i] = 1e-3;  // next band: (almost) none for it
      size_t helper = n;
      for (size_t j = 0; j < n && helper == n; ++j)
        if (errors[j].empty()) helper = j;
      if (helper == n) throw std::runtime_error(errors[i]);
      const std::string first_error = errors[i];
      render_part(helper, cuts[i], cuts[i + 1]);
      if (!errors[helper].empty()) throw std::runtime_error(first_error + "; then " + errors[helper]);
      complete_work = false;
    }
    std::vector<float> work;
    if (!complete_work) return work;
    for (size_t i = 0; i < n; ++i) work.insert(work.end(), results[i].row_work.begin(), results[i].row_work.end());
    return work;
  }

  std::vector<std::unique_ptr<core::Tracer>> tracers_;
  NodeOptions options_;
  std::vector<double> rows_per_ms_;
  BandSlot slots_[2];
  size_t next_slot_ = 0;
  std::vector<BandSlot> retired_;  // band buffers whose pieces had not left (rank 0 stopped reading)
  std::optional<Ahead> ahead_;     // the last job ahead, until a band adopts it or another job comes
  double idle_ms_ = 0.0;           // waiting for rank 0 since the last band
  bool short_piece_sent_ = false;
  uint64_t adopted_ = 0;
  bool diverged_ = false;
  std::string divergence_;
  bool stalled_ = false;
  double commit_ms_ = 0.0;        // applying commits since the last band, with the next job waiting
  double commit_ahead_ms_ = 0.0;  // applying commits since the last band, before the next job came
  double resync_ms_ = 0.0;        // decoding and applying the last full resync, for the ready message
  uint64_t bands_ = 0;
  // The rows' bytes sent (colour in the format rank 0 asked for, which says how many a pixel), for the log.
  uint64_t colour_bytes_sent_ = 0;
  core::BandFormat last_format_ = core::BandFormat::rgb16f;
};

}  // namespace

void join_session(const std::string& port_file, int slot, std::chrono::seconds timeout) {
  const auto deadline = MpiClock::now() + timeout;
  std::string host;
  int port = 0;
  for (;;) {
    std::ifstream in(port_file);
    if (in >> host >> port && port > 0) break;
    if (MpiClock::now() >= deadline)
      throw std::runtime_error(fmt::format("no port in {} after {} s: is rank 0 running with --node-port {}?", port_file,
                                           timeout.count(), port_file));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const auto start = MpiClock::now();
  const int socket = join_socket::connect_within(
      host, port, std::chrono::duration_cast<std::chrono::milliseconds>(deadline - MpiClock::now()));
  if (!join_socket::send_all(socket, join_socket::kMagic)) {
    join_socket::close_socket(socket);
    throw std::runtime_error(fmt::format("rank 0's port {}:{} closed the connection", host, port));
  }
  MpiSession& mpi = MpiSession::get();
  // MPI_Comm_join cannot be cancelled: past the deadline a watchdog ends the process with the reason.
  auto joined = std::make_shared<std::atomic<bool>>(false);
  std::thread([joined, deadline, host, port, seconds = timeout.count()] {
    while (!joined->load() && MpiClock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (joined->load()) return;
    spdlog::error("node: MPI_Comm_join with rank 0 ({}:{}) did not complete within {} s; leaving. With Open MPI, rank "
                  "0's and this node's mpirun need the same name server (--ompi-server file:URI; docs/cluster.md)",
                  host, port, seconds);
    std::fflush(nullptr);
    std::_Exit(1);
  }).detach();
  mpi.join(socket, slot);
  joined->store(true);
  join_socket::close_socket(socket);
  spdlog::info("node: joined rank 0's session through {}:{} in {:.0f} ms", host, port, ms_since(start));
}

int run_node(std::vector<std::unique_ptr<core::Tracer>> tracers, const NodeOptions& options) {
  MpiSession& mpi = MpiSession::get();
  if (mpi.rank() == 0 && !mpi.joined())
    throw std::runtime_error("cohort node runs on ranks 1 and up, or joins rank 0 through its port (--join); rank 0 "
                             "runs `cohort render` or `cohort play` (docs/cluster.md)");
  // Through a port, the slot asked for comes first: rank 0 greets a newcomer before it knows what it serves.
  if (mpi.joined()) send(mpi, wire::Kind::join, 0, wire::encode_join(uint32_t(mpi.rank())));
  if (!options.load_error.empty()) {
    spdlog::error("node {}: {}; leaving", mpi.rank(), options.load_error);
    send(mpi, wire::Kind::load_failed, 0, wire::encode_text(options.load_error));
    mpi.flush_sends(kRank0, MpiClock::now() + std::chrono::seconds(10));
    return 1;
  }
  if (tracers.empty()) throw std::runtime_error("cohort node: no tracers");
  wire::Hello hello;
  hello.cohort_version = options.announced_version.empty() ? wire::cohort_version() : options.announced_version;
  hello.host = host_name();
  hello.tracers = options.tracers_text;
  hello.scene_fingerprint = options.scene ? wire::scene_fingerprint(*options.scene) : 0;
  hello.scene_name = options.scene_name;
  send(mpi, wire::Kind::hello, 0, wire::encode_hello(hello));
  // The answer: welcome, or refuse with the reason (versions disagree).
  for (;;) {
    std::optional<wire::Message> received = receive_from_rank0(mpi, options.idle_timeout);
    if (!received) {
      spdlog::error("node {}: rank 0 did not answer the hello within {} s; leaving", mpi.rank(),
                    options.idle_timeout.count());
      return 1;
    }
    const wire::Message& m = *received;
    if (m.kind == wire::Kind::refuse) {
      spdlog::error("node {}: rank 0 refused this node: {}", mpi.rank(), wire::decode_text(m.payload));
      return 1;
    }
    if (m.kind == wire::Kind::shutdown) return 0;  // rank 0 ended before it needed this node
    if (m.kind == wire::Kind::welcome) {
      if (!m.payload.empty()) {  // through a port: the slot rank 0 gave it
        try {
          spdlog::info("node: rank 0 welcomed this node as {}", wire::decode_text(m.payload));
        } catch (const wire::WireError& e) {
          spdlog::warn("node: unreadable welcome: {}", e.what());
        }
      }
      break;
    }
    spdlog::warn("node {}: ignored a {} message before the welcome", mpi.rank(), wire::to_string(m.kind));
  }
  spdlog::info("node {}: serving rank 0 with {}", mpi.rank(), options.tracers_text);
  Node node(std::move(tracers), options);
  return node.serve(mpi);
}

}  // namespace cohort::tracers
