#include "cohort/core/renderer.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <spdlog/spdlog.h>

#include "cohort/core/brief_spin.h"
#include "cohort/core/host_threads.h"

namespace cohort::core {

using Clock = std::chrono::steady_clock;

namespace {

constexpr size_t kRowsPerCopy = 16;  // a band's rows are merged into the frame in ranges this size or larger

// Signalled by workers when a job ends; the core waits on it.
struct Completion {
  std::mutex mutex;
  std::condition_variable cv;
  std::atomic<uint64_t> count{0};  // jobs ended so far: what the core polls before it blocks
};

}  // namespace

struct Renderer::Worker {
  int id = 0;
  std::unique_ptr<Tracer> tracer;
  std::string name;  // asked once: the tracer may be busy on its own thread whenever the core looks
  std::shared_ptr<Completion> completion;

  // One job handed out and not yet started.
  struct Queued {
    uint64_t id = 0;
    BandJob job;
    bool recovery = false;  // re-rendering rows a dropped tracer did not deliver
    bool probe = false;     // rendering rows only to be measured (a benched tracer)
    bool away = false;      // its commits on the side while the tracer is away (Tracer::while_away)
    int slot = 0;           // which of the two targets the job renders into
    // Taken from the channel by the core at hand-out; the job owns it, so that the core may hand out the
    // next job (and take the next commit) while this one's is still being applied. Applied ahead, by a
    // tracer that takes commits ahead, while the job before renders: then it is gone from here.
    std::optional<commit::CommitBuffer> commit;
    // The channel the job's tracer may take commits ahead from (Tracer::takes_commits_ahead), handed over
    // with the job: the core creates a channel on its first submit_commit, which may come while a job runs.
    commit::CommitChannel* channel = nullptr;
    // Handed to the tracer ahead (Tracer::queued_next) while the job before rendered: its commit is applied
    // and its commands may be in the device's queue already.
    bool enqueued_ahead = false;
    // When the core put it in the inbox: after the worker's job before had ended, the worker waited for it.
    Clock::time_point posted{};
  };

  // Inbox, guarded by inbox_mutex: at most two frames' jobs, and a recovery job behind them.
  std::mutex inbox_mutex;
  std::condition_variable inbox_cv;
  bool quit = false;
  std::deque<Queued> inbox;
  std::atomic<bool> job_posted{false};  // !inbox.empty(), for polling without the lock
  std::chrono::microseconds handoff_spin{0};  // RendererOptions::handoff_spin
  bool two_in_flight = false;                 // RendererOptions::frames_in_flight == 2
  bool woken = false;  // guarded by inbox_mutex: the tracer's wake_queued_next() since queued_next looked
  // Core thread only: when this worker's last job handed out should end, and its last wall time.
  Clock::time_point expected_end{};
  double last_wall_ms = 0.0;

  // Created by the first submit_commit; publish and take are the core's, the channel locks itself.
  std::shared_ptr<commit::CommitChannel> channel;
  // Worker thread only: an apply threw, so the tracer's scene no longer matches the core's until a
  // full resync has been applied.
  bool scene_diverged = false;
  // Worker thread only: while a job of a tracer that takes commits ahead renders, its channel, and the
  // stages of what it applied ahead.
  commit::CommitChannel* ahead_channel = nullptr;
  std::vector<StageSpan> ahead_spans;
  // Worker thread only: a job was handed to the tracer ahead (Tracer::queued_next) and has not started yet;
  // if it never does (shutdown drops it), the tracer drains it before the thread ends.
  bool handed_ahead = false;
  // Worker thread only: when its last job ended (for the time it waited for the next).
  std::optional<Clock::time_point> last_end;
  // Core thread only: the unwaited jobs of a benched tracer (at most one a frame in flight) with their
  // probe bands, and the rows per ms this tracer showed last (how much of a dropped tracer's rows it is
  // given).
  struct SideJob {
    uint64_t id = 0;
    balance::Band band;
  };
  std::vector<SideJob> side_jobs;
  double rows_per_ms = 0.0;
  int benched_frames_without_job = 0;  // frames benched since its last side job (RendererOptions::benched_commit_every)
  // Core thread: whether a benched or away tracer is handed its side job this frame: at once when `now` (a
  // probe to render, a full resync asked for), else every `every` frames, its commits coalescing meanwhile.
  bool side_job_due(bool now, int every) {
    if (!now && ++benched_frames_without_job < every) return false;
    benched_frames_without_job = 0;
    return true;
  }

  // Guarded by completion->mutex: the jobs handed out that have not ended, and what the ended ones
  // reported until the core takes it.
  std::vector<uint64_t> unfinished;
  std::deque<Outcome> outcomes;

  bool busy() const { return !unfinished.empty(); }
  // The outcome of job `job_id`, taken out of the list; nothing while it has not ended. Call with
  // completion->mutex held.
  std::optional<Outcome> take_outcome(uint64_t job_id) {
    for (auto it = outcomes.begin(); it != outcomes.end(); ++it) {
      if (it->job_id != job_id) continue;
      Outcome o = std::move(*it);
      outcomes.erase(it);
      return o;
    }
    return std::nullopt;
  }
  bool ended(uint64_t job_id) const {
    return std::find(unfinished.begin(), unfinished.end(), job_id) == unfinished.end();
  }

  // The tracer's private targets, one per frame parity, so that the core merges frame N from one
  // while the tracer renders N+1 into the other. Only the worker writes a target while its job runs;
  // the core reads a finished job's rows until it hands out a job for the same slot again.
  BandBuffer targets[2];
  std::thread thread;

  void loop() {
    for (;;) {
      Queued current;
      if (handoff_spin.count() > 0)
        spin_until(Clock::now() + handoff_spin, [&] { return job_posted.load(std::memory_order_acquire); });
      {
        std::unique_lock lock(inbox_mutex);
        inbox_cv.wait(lock, [&] { return quit || !inbox.empty(); });
        if (quit && inbox.empty()) {
          lock.unlock();
          drop_ahead();
          return;
        }
        current = std::move(inbox.front());
        inbox.pop_front();
        job_posted.store(!inbox.empty(), std::memory_order_relaxed);
      }
      Outcome outcome;
      outcome.job_id = current.id;
      const auto start = Clock::now();
      if (last_end) outcome.waited_ms = std::chrono::duration<double, std::milli>(start - *last_end).count();
      const std::string track = tracer_track(id, name);
      if (last_end && current.posted > *last_end) {
        // Starved: its band before ended with no job queued (docs/balancing.md, "The next frame handed out
        // as soon as a slot frees"). On the timeline only with two in flight, where the job should have been
        // queued (the span starts before its frame's hand-out); with one, every band waits for the frame's
        // turnaround by design.
        outcome.job_wait_ms = std::chrono::duration<double, std::milli>(current.posted - *last_end).count();
        if (two_in_flight) outcome.spans.push_back({track, "wait for job", timeline_ms(*last_end), outcome.job_wait_ms});
      }
      if (current.enqueued_ahead) handed_ahead = false;
      bool rendered = false;  // whether render_band took the job (one enqueued ahead is then its business)
      try {
        if (current.away) tracer->while_away();
        // Apply time is part of what the tracer costs the frame, so the balancer sees it: the apply's own
        // time, nothing when there is nothing to apply (the clock's jitter around an empty step would reach
        // the costs of tracers on a virtual clock, RendererOptions::use_reported_time, and move their rows).
        if (current.commit && !current.commit->empty()) {
          const auto apply_start = Clock::now();
          apply(*current.commit, outcome.spans, track);
          outcome.apply_ms = std::chrono::duration<double, std::milli>(Clock::now() - apply_start).count();
        }
        if (scene_diverged)
          throw std::runtime_error("its scene diverged after a failed commit; waiting for a full resync");
        const BandJob& job = current.job;
        if (job.params.row_end > job.params.row_begin) {  // a benched tracer may only apply
          ScopedStage rendering(outcome.spans, track, current.recovery ? "re-render" : current.probe ? "probe" : "render");
          if (tracer->takes_commits_ahead()) ahead_channel = current.channel;
          BandResult result;
          try {
            rendered = true;
            result = tracer->render_band(job, targets[current.slot]);
          } catch (...) {
            end_ahead(outcome.spans);
            throw;
          }
          end_ahead(outcome.spans);
          outcome.wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
          rendering.finish();
          if (result.transfer_ms > 0.0) {
            // The tracer's own clock inside its render span: kernels then transfer, ending with the span.
            const StageSpan render = outcome.spans.back();
            append_spans_ending_at(outcome.spans, track, render.start_ms + render.ms,
                                   {{"kernels", result.device_ms}, {"transfer", result.transfer_ms}}, render.start_ms);
          }
          outcome.reported_ms = result.device_ms;
          outcome.balance_ms = result.balance_ms;
          if (result.row_work.size() == job.params.row_end - job.params.row_begin) outcome.row_work = std::move(result.row_work);
          if (job.keep_on_device >= 0) outcome.device_band = result.device;
        } else {
          outcome.wall_ms = outcome.apply_ms;
        }
        outcome.ok = true;
      } catch (const std::exception& e) {
        outcome.error = e.what();
      } catch (...) {
        outcome.error = "unknown exception";
      }
      // Enqueued ahead but not rendered (its scene diverged): nothing may write its target once it has ended.
      if (current.enqueued_ahead && !rendered) tracer->drop_enqueued_ahead();
      current.commit.reset();  // the records (and a resync's scene) are not kept for the next job's wait
      last_end = Clock::now();
      {
        std::lock_guard lock(completion->mutex);
        std::erase(unfinished, current.id);
        outcomes.push_back(std::move(outcome));
        completion->count.fetch_add(1, std::memory_order_release);
      }
      completion->cv.notify_all();
    }
  }

  // Tracer::apply_commits_ahead, on this worker's thread inside render_band. With the next job already
  // queued (two frames in flight), that job's commit is what the core published after this one's: it is
  // applied now, and what is published after it stays in the channel for the job after. Otherwise what the
  // core published since the job was handed out is applied now; the next job brings what is published
  // after it. Not while a resync is asked for or the scene diverged: the next job's commit answers those,
  // as always.
  void apply_ahead() {
    commit::CommitChannel* channel_now = ahead_channel;
    if (!channel_now || scene_diverged) return;
    std::optional<commit::CommitBuffer> queued;
    const commit::CommitBuffer* commit = nullptr;
    {
      std::lock_guard lock(inbox_mutex);  // the core takes from the channel under it when it queues a job
      if (!inbox.empty()) {
        Queued& next = inbox.front();
        if (next.recovery || !next.commit) return;
        queued = std::move(next.commit);
        next.commit.reset();
        commit = &*queued;
      } else {
        if (!channel_now->has_pending() || channel_now->resync_requested()) return;
        commit = &channel_now->begin_frame();
      }
    }
    if (commit->empty()) return;
    try {
      apply(*commit, ahead_spans, tracer_track(id, name), " ahead");
    } catch (...) {
      // apply() marked the scene diverged and asked for a resync: the next job fails until it comes.
    }
  }
  // Tracer::queued_next, on this worker's thread inside render_band: the next job when it is queued with
  // final rows (two frames in flight; not a recovery job, a probe or an away tracer's side job), its commit
  // applied here first (with the stages of what was applied ahead; the job no longer brings it). Not while
  // the scene diverged or when the job brings a full resync: that one is applied as always, when its job
  // starts, and its band enqueued then.
  // With two in flight it waits for the job until the band is done (band_done, polled every millisecond
  // besides the tracer's wake-ups): the core hands it out once it has turned the frame before around. Once
  // the band is done it stops waiting: a job that comes later starts as usual (there is nothing left to
  // overlap, and enqueueing it first would only hold back the band's return, for which the core waits).
  std::optional<Tracer::QueuedNext> queued_next(const Tracer::BandDone& band_done) {
    if (scene_diverged) return std::nullopt;
    std::optional<commit::CommitBuffer> commit;
    Tracer::QueuedNext next;
    {
      std::unique_lock lock(inbox_mutex);
      if (two_in_flight && band_done) {
        woken = false;
        while (!quit && inbox.empty()) {
          // Outside the lock: band_done may ask the device, whose completion callback may be taking it (wake).
          lock.unlock();
          const bool done = band_done();
          lock.lock();
          if (done) return std::nullopt;
          inbox_cv.wait_for(lock, std::chrono::milliseconds(1), [&] { return quit || !inbox.empty() || woken; });
          woken = false;
        }
      }
      if (quit || inbox.empty()) return std::nullopt;
      Queued& queued = inbox.front();
      if (queued.recovery || queued.probe || queued.away || queued.enqueued_ahead ||
          queued.job.params.row_end <= queued.job.params.row_begin)
        return std::nullopt;
      if (queued.commit && queued.commit->is_full_resync()) {
        spdlog::debug("tracer {} ({}): not enqueueing ahead, the next job brings a full resync", id, name);
        return std::nullopt;
      }
      commit = std::move(queued.commit);
      queued.commit.reset();
      queued.enqueued_ahead = true;
      next.job = queued.job;
      next.target = &targets[queued.slot];
    }
    handed_ahead = true;
    if (commit && !commit->empty()) {
      try {
        apply(*commit, ahead_spans, tracer_track(id, name), " ahead");
      } catch (...) {
        // apply() marked the scene diverged and asked for a resync: the job fails when it starts.
        return std::nullopt;
      }
    }
    return next;
  }
  void wake() {
    {
      std::lock_guard lock(inbox_mutex);
      woken = true;
    }
    inbox_cv.notify_all();
  }
  void drop_ahead() {
    if (!handed_ahead) return;
    handed_ahead = false;
    tracer->drop_enqueued_ahead();
  }
  // Tracer::next_job_announced: the job this worker renders next, when it is queued already (without its
  // rows, as an announcement has none), else the core's announcement.
  std::optional<BandJob> next_job(const std::shared_ptr<Announcement>& announcement) {
    {
      std::lock_guard lock(inbox_mutex);
      if (!inbox.empty()) {
        const Queued& next = inbox.front();
        if (next.recovery || next.probe || next.job.params.row_end <= next.job.params.row_begin) return std::nullopt;
        BandJob job = next.job;
        job.params.row_begin = job.params.row_end = 0;
        job.keep_on_device = -1;
        return job;
      }
    }
    std::lock_guard lock(announcement->mutex);
    return announcement->job;
  }
  void end_ahead(std::vector<StageSpan>& spans) {
    ahead_channel = nullptr;
    spans.insert(spans.end(), std::make_move_iterator(ahead_spans.begin()), std::make_move_iterator(ahead_spans.end()));
    ahead_spans.clear();
  }

  void apply(const commit::CommitBuffer& commit, std::vector<StageSpan>& spans, const std::string& track,
             const char* when = "") {
    ScopedStage applying(spans, track,
                         std::string(commit.is_full_resync() ? "apply (full resync)" : "apply") + when);
    try {
      tracer->apply(commit);
    } catch (...) {
      scene_diverged = true;
      channel->request_resync();
      throw;
    }
    if (commit.is_full_resync()) scene_diverged = false;
  }
};

Renderer::Renderer(std::vector<std::unique_ptr<Tracer>> tracers, RendererOptions options)
    : options_(std::move(options)) {
  if (tracers.empty()) throw std::invalid_argument("Renderer: no tracers");
  if (options_.frames_in_flight != 1 && options_.frames_in_flight != 2)
    throw std::invalid_argument("Renderer: frames_in_flight is 1 or 2, not " + std::to_string(options_.frames_in_flight));
  balancer_ = balance::make_balancer(options_.balancer, options_.balancer_options);
  auto completion = std::make_shared<Completion>();
  for (size_t i = 0; i < tracers.size(); ++i) {
    if (!tracers[i]) throw std::invalid_argument("Renderer: tracer " + std::to_string(i) + " is null");
    auto w = std::make_shared<Worker>();
    w->id = static_cast<int>(i);
    w->tracer = std::move(tracers[i]);
    w->name = w->tracer->name();
    w->completion = completion;
    w->handoff_spin = options_.handoff_spin;
    // The worker owns the tracer, so the hook never outlives what it points at.
    if (w->tracer->takes_commits_ahead()) w->tracer->set_commits_ahead([worker = w.get()] { worker->apply_ahead(); });
    w->two_in_flight = options_.frames_in_flight == 2;
    if (w->tracer->enqueues_ahead())
      w->tracer->set_queued_next([worker = w.get()](const Tracer::BandDone& done) { return worker->queued_next(done); },
                                 [worker = w.get()] { worker->wake(); });
    if (w->tracer->takes_jobs_ahead()) {
      any_takes_jobs_ahead_ = true;
      w->tracer->set_next_job([worker = w.get(), announcement = announcement_]() -> std::optional<BandJob> {
        return worker->next_job(announcement);
      });
    }
    workers_.push_back(std::move(w));
  }
  // Each thread shares its worker, so a worker whose tracer never returns can be left behind at
  // shutdown with its tracer, targets and channel alive; the last owner frees them.
  for (auto& w : workers_) w->thread = std::thread([worker = w] { worker->loop(); });
}

Renderer::~Renderer() {
  for (auto& w : workers_) {
    std::deque<Worker::Queued> dropped;  // handed out but not started: they never will be
    {
      std::lock_guard lock(w->inbox_mutex);
      w->quit = true;
      dropped.swap(w->inbox);
    }
    {
      std::lock_guard lock(w->completion->mutex);
      for (const Worker::Queued& job : dropped) std::erase(w->unfinished, job.id);
    }
    w->inbox_cv.notify_all();
  }
  // A tracer still inside apply() or render_band() gets until the shutdown deadline; one that has not
  // returned by then (a hung device, a driver that never comes back) must not hang the process too.
  const auto deadline = Clock::now() + options_.shutdown_timeout;
  Completion& completion = *workers_.front()->completion;
  for (auto& w : workers_) {
    bool returned = false;
    {
      std::unique_lock lock(completion.mutex);
      returned = completion.cv.wait_until(lock, deadline, [&] { return !w->busy(); });
    }
    if (returned) {
      w->thread.join();
    } else {
      spdlog::error("Renderer shutdown: tracer {} ({}) has not returned from its job after {} ms; leaving its "
                    "thread behind (its tracer is freed if it ever returns)",
                    w->id, w->name, options_.shutdown_timeout.count());
      w->thread.detach();
    }
  }
}

void Renderer::submit_commit(const commit::CommitBuffer& records, commit::CommitChannel::Snapshot snapshot) {
  if (records.is_full_resync()) {
    full_scene_ = records.shared_full_scene();
    records_since_full_ = false;
    if (!snapshot) snapshot_ = {};
  } else if (!records.empty()) {
    records_since_full_ = true;
  }
  if (snapshot) snapshot_ = std::move(snapshot);
  commit_frame_ = records.frame();
  for (auto& w : workers_) {
    if (!w->channel) {
      // The first commit seeds the channel: a full one as its initial resync, else an empty scene
      // that the records then build on.
      const bool full = records.is_full_resync();
      w->channel = std::make_shared<commit::CommitChannel>(
          options_.commit_budget_bytes, full ? full_scene_ : std::make_shared<const commit::TracerScene>(),
          records.frame());
      if (full) continue;
    }
    w->channel->publish(records, [this] { return resync_scene(); });
  }
}

std::shared_ptr<const commit::TracerScene> Renderer::resync_scene() {
  if (snapshot_) return snapshot_();
  if (full_scene_ && !records_since_full_) return full_scene_;
  throw std::logic_error("Renderer: a tracer needs a full resync, but incremental commits were submitted without a "
                         "snapshot of the scene they build (pass WorldSync::snapshot to submit_commit)");
}

commit::CommitStats Renderer::commit_stats(int tracer) const {
  const Worker& w = *workers_.at(static_cast<size_t>(tracer));
  return w.channel ? w.channel->stats() : commit::CommitStats{};
}

int Renderer::tracer_count() const { return static_cast<int>(workers_.size()); }
std::string Renderer::tracer_name(int tracer) const { return workers_.at(static_cast<size_t>(tracer))->name; }

void Renderer::set_balancer(const std::string& name) {
  std::unique_ptr<balance::Balancer> next = balance::make_balancer(name, options_.balancer_options);
  balancer_ = std::move(next);
  options_.balancer = name;
  last_measurements_.clear();
}

void Renderer::reset_balancer() {
  balancer_->reset();
  last_measurements_.clear();
}

double Renderer::measured_ms(const Outcome& o) const {
  // Reported times are the tracer's own (kernel time); its commit apply is part of its cost too.
  if (options_.use_reported_time && o.reported_ms > 0.0) return o.reported_ms + o.apply_ms;
  return o.balance_ms > 0.0 ? o.balance_ms + o.apply_ms : o.wall_ms;
}

const Renderer::Outcome& Renderer::RoundResult::of(int worker) const {
  for (const auto& [id, outcome] : outcomes)
    if (id == worker) return outcome;
  throw std::logic_error("Renderer: no outcome of tracer " + std::to_string(worker) + " in this round");
}

void Renderer::harvest_side_job(Worker& w, std::vector<StageSpan>& stages) {
  for (auto side = w.side_jobs.begin(); side != w.side_jobs.end();) {
    std::optional<Outcome> o = w.take_outcome(side->id);
    if (!o) {
      if (w.ended(side->id)) {
        side = w.side_jobs.erase(side);  // ended, and its outcome pruned (a frame that moved on)
      } else {
        ++side;
      }
      continue;
    }
    const balance::Band band = side->band;
    side = w.side_jobs.erase(side);
    stages.insert(stages.end(), std::make_move_iterator(o->spans.begin()), std::make_move_iterator(o->spans.end()));
    if (!o->ok) {
      spdlog::warn("tracer {} ({}) failed while benched{}: {}", w.id, w.name, band.empty() ? "" : " on its probe band", o->error);
      continue;
    }
    if (band.empty()) continue;
    const double ms = measured_ms(*o);
    std::erase_if(last_measurements_, [&](const balance::TracerMeasurement& m) { return m.tracer == w.id; });
    last_measurements_.push_back({w.id, band, ms});
    if (ms > 0.0) w.rows_per_ms = band.rows() / ms;
  }
}

std::vector<uint64_t> Renderer::assign(std::vector<Assignment>& assignments, const BandJob& job, int slot,
                                       bool with_commits) {
  const int width = static_cast<int>(job.camera.width), height = static_cast<int>(job.camera.height);
  std::vector<uint64_t> ids(assignments.size());
  for (size_t i = 0; i < assignments.size(); ++i) {
    Worker& w = *workers_[static_cast<size_t>(assignments[i].worker)];
    // Only the worker's job of the other slot may be running: this slot's target is the core's.
    w.targets[slot].resize(width, height, options_.band_format);
    w.targets[slot].enable_aux(job.params.aux_outputs != 0u);
    ids[i] = next_job_++;
    const auto now = Clock::now();
    {
      std::lock_guard lock(w.completion->mutex);
      // Queued behind a job still running, it starts when that one ends.
      const Clock::time_point begins = w.busy() ? std::max(now, w.expected_end) : now;
      w.unfinished.push_back(ids[i]);
      w.expected_end = begins + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double, std::milli>(w.last_wall_ms));
      assignments[i].due = w.expected_end;
    }
    Worker::Queued queued;
    queued.id = ids[i];
    queued.job = job;
    queued.job.params.row_begin = static_cast<kuint>(assignments[i].band.begin);
    queued.job.params.row_end = static_cast<kuint>(assignments[i].band.end);
    queued.channel = w.channel.get();
    queued.recovery = !with_commits;
    queued.slot = slot;
    queued.probe = assignments[i].probe;
    queued.away = assignments[i].away;
    // Only a frame's own bands may stay on a GPU: re-rendered rows and probes come through the host.
    queued.job.keep_on_device = with_commits && !assignments[i].probe && packed_merge_ ? device_bands_for_ : -1;
    std::lock_guard lock(w.inbox_mutex);
    // What was published so far belongs to this frame; commits submitted from now on wait for the
    // next. Re-rendering a dropped tracer's rows happens within the same frame, so it takes none.
    if (with_commits && w.channel) {
      if (w.tracer->wants_full_resync()) w.channel->request_resync();
      if (w.channel->resync_requested()) {  // answer a failed apply even when the scene is still
        commit::CommitBuffer nothing_new;
        nothing_new.set_frame(commit_frame_);
        w.channel->publish(nothing_new, [this] { return resync_scene(); });
      }
      queued.commit.emplace();
      w.channel->take(*queued.commit);
    }
    queued.posted = Clock::now();
    w.inbox.push_back(std::move(queued));
    w.job_posted.store(true, std::memory_order_release);
    w.inbox_cv.notify_one();
  }
  return ids;
}

Renderer::RoundResult Renderer::collect(const std::vector<Assignment>& assignments, const std::vector<uint64_t>& ids,
                                        Clock::time_point deadline, std::vector<StageSpan>& stages) {
  RoundResult result;
  if (assignments.empty()) return result;
  Completion& completion = *workers_.front()->completion;
  std::unique_lock lock(completion.mutex);
  auto all_done = [&] {
    for (size_t i = 0; i < assignments.size(); ++i) {
      if (!workers_[static_cast<size_t>(assignments[i].worker)]->ended(ids[i])) return false;
    }
    return true;
  };
  if (options_.handoff_spin.count() > 0 && !all_done()) {
    // Asleep until shortly before the slowest band is due, then polling the count of ended jobs.
    Clock::time_point due{};
    for (const Assignment& a : assignments) due = std::max(due, a.due);
    const auto spin = std::chrono::duration_cast<Clock::duration>(options_.handoff_spin);
    completion.cv.wait_until(lock, std::min(due - spin, deadline), all_done);
    uint64_t seen = completion.count.load(std::memory_order_acquire);
    const auto spin_end = std::min(std::max(due, Clock::now()) + spin, deadline);
    while (!all_done()) {
      lock.unlock();
      const bool ended = spin_until(spin_end, [&] { return completion.count.load(std::memory_order_acquire) != seen; });
      lock.lock();
      if (!ended) break;
      seen = completion.count.load(std::memory_order_acquire);
    }
  }
  completion.cv.wait_until(lock, deadline, all_done);
  for (size_t i = 0; i < assignments.size(); ++i) {
    Worker& w = *workers_[static_cast<size_t>(assignments[i].worker)];
    std::optional<Outcome> o = w.take_outcome(ids[i]);
    if (!o) {
      result.timed_out.push_back(w.id);
      continue;
    }
    stages.insert(stages.end(), std::make_move_iterator(o->spans.begin()), std::make_move_iterator(o->spans.end()));
    o->spans.clear();
    if (o->ok) w.last_wall_ms = o->wall_ms;
    if (!o->ok) {
      result.threw.push_back(w.id);
    } else {
      result.finished.push_back(w.id);
      result.delivered.push_back(assignments[i]);
      result.delivered.back().device = o->device_band;
      const balance::Band& band = assignments[i].band;
      if (o->row_work.size() == static_cast<size_t>(band.rows()) && static_cast<int>(row_work_.size()) >= band.end) {
        std::copy(o->row_work.begin(), o->row_work.end(), row_work_.begin() + band.begin);
        std::fill(row_work_known_.begin() + band.begin, row_work_known_.begin() + band.end, 1);
      }
    }
    result.outcomes.emplace_back(w.id, std::move(*o));
  }
  return result;
}

void Renderer::for_band_rows(const std::vector<Assignment>& bands, int slot,
                             const std::function<void(const BandBuffer&, int, int)>& copy) const {
  for (const Assignment& a : bands) {
    const BandBuffer& target = workers_[static_cast<size_t>(a.worker)]->targets[slot];
    HostThreads::shared().for_ranges(static_cast<size_t>(a.band.rows()), kRowsPerCopy, [&](size_t begin, size_t end) {
      copy(target, a.band.begin + static_cast<int>(begin), a.band.begin + static_cast<int>(end));
    });
  }
}

void Renderer::merge(const std::vector<Assignment>& bands, int slot, FrameBuffer& out) const {
  for_band_rows(bands, slot, [&](const BandBuffer& target, int begin, int end) { target.copy_rows_to(out, begin, end); });
}

FrameStats Renderer::render(const BandJob& job, FrameBuffer& out, const std::vector<float>& row_cost_proxy) {
  if (!pending_.empty()) throw std::logic_error("Renderer::render: a frame is in flight");
  begin_frame(job, out, row_cost_proxy);
  return finish_frame();
}

void Renderer::announce_frame(const BandJob& job) {
  std::lock_guard lock(announcement_->mutex);
  announcement_->job = job;
  announcement_->job->params.row_begin = announcement_->job->params.row_end = 0;
  announcement_->job->keep_on_device = -1;
}

void Renderer::begin_frame(const BandJob& job, FrameBuffer& out, const std::vector<float>& row_cost_proxy) {
  if (static_cast<int>(pending_.size()) >= options_.frames_in_flight)
    throw std::logic_error("Renderer::begin_frame: the previous frame was not waited for");
  if (unmerged_ && unmerged_->slot == next_slot_)
    throw std::logic_error("Renderer::begin_frame: the frame before the previous one was not merged");
  {
    std::lock_guard lock(announcement_->mutex);
    announcement_->job.reset();  // from here on, this frame's jobs say what it is
  }
  const auto frame_start = Clock::now();
  const int width = static_cast<int>(job.camera.width), rows = static_cast<int>(job.camera.height);
  if (width <= 0 || rows <= 0) throw std::invalid_argument("Renderer::render: camera has no pixels");

  FrameStats stats;
  stats.frame = job.params.frame_index;
  stats.rows = rows;
  stats.balancer = options_.balancer;
  stats.tracers.resize(workers_.size());
  stats.start_ms = timeline_ms(frame_start);

  // Tracers still finishing late work sit this frame out; the balancer sees them as removed. With two
  // frames in flight, a tracer whose one unfinished job belongs to the frame in flight is ready: this
  // frame's job queues behind it.
  const PendingFrame* in_flight = pending_.empty() ? nullptr : pending_.back().get();
  std::vector<int> ready, away;
  {
    std::lock_guard lock(workers_.front()->completion->mutex);
    for (auto& w : workers_) {
      harvest_side_job(*w, stats.stages);
      // What nobody will collect any more (late jobs of frames that moved on) is dropped.
      std::erase_if(w->outcomes, [&](const Outcome& o) {
        const auto wanted = [&](uint64_t id) { return id == o.job_id; };
        return !(in_flight && std::any_of(in_flight->handed_out.begin(), in_flight->handed_out.end(), wanted)) &&
               !std::any_of(w->side_jobs.begin(), w->side_jobs.end(), [&](const Worker::SideJob& j) { return wanted(j.id); });
      });
      TracerFrameStats& t = stats.tracers[static_cast<size_t>(w->id)];
      t.id = w->id;
      t.name = w->name;
      const bool queues_behind_the_frame_in_flight =
          in_flight && w->unfinished.size() == 1 &&
          std::find(in_flight->handed_out.begin(), in_flight->handed_out.end(), w->unfinished.front()) !=
              in_flight->handed_out.end();
      if (w->busy() && !queues_behind_the_frame_in_flight) t.outcome = TracerOutcome::busy;
      else if (!w->tracer->available()) away.push_back(w->id);
      else ready.push_back(w->id);
    }
  }
  // Nobody else left: those away are asked anyway (their bands fail, and the frame says why).
  if (ready.empty()) ready.swap(away);
  if (ready.empty()) throw std::runtime_error("frame " + std::to_string(stats.frame) + ": every tracer is still busy with an earlier frame");

  // Without a proxy from the caller, last frame's per-row work counts serve, when every row has one.
  std::vector<float> proxy = row_cost_proxy;
  if (proxy.empty() && options_.use_row_work && static_cast<int>(row_work_.size()) == rows &&
      std::all_of(row_work_known_.begin(), row_work_known_.end(), [](uint8_t k) { return k != 0; }))
    proxy = row_work_;
  row_work_.assign(static_cast<size_t>(rows), 0.0f);
  row_work_known_.assign(static_cast<size_t>(rows), 0);
  ScopedStage balancing(stats.stages, kCoreTrack, "balance");
  // The interval since the previous frame began is what the loop delivers (with a virtual clock it
  // means nothing, and the balancer gets none).
  double interval_ms = 0.0, since_previous_ms = 0.0;
  if (last_frame_start_) since_previous_ms = std::chrono::duration<double, std::milli>(frame_start - *last_frame_start_).count();
  if (!options_.use_reported_time) interval_ms = since_previous_ms;
  last_frame_start_ = frame_start;
  const std::vector<balance::Band> bands =
      balancer_->divide({rows, ready, last_measurements_, std::move(proxy), interval_ms});
  const std::vector<balance::Band> probes = balancer_->probe_bands();
  for (const balance::SitOutVerdict& v : balancer_->take_verdicts()) {
    const std::string& name = workers_[static_cast<size_t>(v.tracer)]->name;
    spdlog::info("{} {}: frames took {:.3f} ms with its rows, {:.3f} ms with them handed to the others (medians of {} "
                 "frames each); tried again in {} frames",
                 name, v.sits_out ? "sits out" : "keeps its rows", v.with_ms, v.without_ms, v.frames_each,
                 v.next_trial_in);
  }
  balancing.finish();
  std::vector<Assignment> assignments, side_jobs;
  for (size_t i = 0; i < ready.size(); ++i) {
    TracerFrameStats& t = stats.tracers[static_cast<size_t>(ready[i])];
    t.row_begin = bands[i].begin;
    t.row_end = bands[i].end;
    if (bands[i].empty()) {
      // Benched: it keeps its scene current (and maybe renders a probe), and nobody waits for it.
      t.outcome = TracerOutcome::no_rows;
      const balance::Band probe = probes.size() == ready.size() ? probes[i] : balance::Band{};
      t.probe_rows = probe.rows();
      Worker& w = *workers_[static_cast<size_t>(ready[i])];
      if (!w.side_job_due(!probe.empty(), options_.benched_commit_every)) continue;
      side_jobs.push_back({ready[i], probe, !probe.empty(), {}});
    } else {
      assignments.push_back({ready[i], bands[i], false, {}});
    }
  }

  // Away: no rows, and nobody waits for it; it keeps its scene current as a benched tracer does (its
  // commits coalesce meanwhile), so that it renders at once when it is back; one that asks for a full resync
  // (a remote tracer whose slot a new node joined) gets it at once, and one that waits for an answer (that
  // node saying it is ready) gets its side job every frame, so that it is back the frame after.
  for (int id : away) {
    stats.tracers[static_cast<size_t>(id)].outcome = TracerOutcome::away;
    Worker& w = *workers_[static_cast<size_t>(id)];
    if (!w.side_job_due(w.tracer->wants_full_resync() || w.tracer->checks_in_every_frame(), options_.benched_commit_every))
      continue;
    side_jobs.push_back({id, {}, false, {}});
    side_jobs.back().away = true;
  }

  const int slot = next_slot_;
  next_slot_ ^= 1;
  std::vector<uint64_t> ids = assign(assignments, job, slot, true);
  // A probe renders into this frame's slot, which the frame never merges from a benched tracer.
  const std::vector<uint64_t> side_ids = assign(side_jobs, job, slot, true);
  for (size_t i = 0; i < side_jobs.size(); ++i) {
    Worker& w = *workers_[static_cast<size_t>(side_jobs[i].worker)];
    w.side_jobs.push_back({side_ids[i], side_jobs[i].band});
  }
  auto frame = std::make_unique<PendingFrame>();
  frame->job = job;
  frame->out = &out;
  frame->stats = std::move(stats);
  frame->assignments = std::move(assignments);
  frame->handed_out = ids;
  frame->handed_out.insert(frame->handed_out.end(), side_ids.begin(), side_ids.end());
  frame->ids = std::move(ids);
  frame->start = frame_start;
  frame->slot = slot;
  frame->since_previous_ms = since_previous_ms;
  pending_.push_back(std::move(frame));
}

FrameStats Renderer::finish_frame() {
  FrameStats stats = wait_frame();
  merge_frame(stats);
  return stats;
}

void Renderer::merge_frame(FrameStats& stats) {
  if (!unmerged_) throw std::logic_error("Renderer::merge_frame: no frame is waiting to be merged");
  std::unique_ptr<PendingFrame> frame = std::move(unmerged_);
  FrameBuffer& out = *frame->out;
  const int width = static_cast<int>(frame->job.camera.width), height = static_cast<int>(frame->job.camera.height);
  ScopedStage merging(stats.stages, kCoreTrack, "merge");
  const bool aux = frame->job.params.aux_outputs != 0u;
  if (packed_merge_) {
    packed_.resize(width, height, options_.band_format);  // keeps its storage (and registration) when unchanged
    packed_.enable_aux(aux);
    packed_device_rows_.clear();
    std::vector<Assignment> on_host;
    for (const Assignment& a : frame->delivered) {
      if (a.device.cuda_device >= 0) packed_device_rows_.push_back({a.band.begin, a.band.end, a.device});
      else on_host.push_back(a);
    }
    for_band_rows(on_host, frame->slot,
                  [&](const BandBuffer& target, int begin, int end) { packed_.copy_rows_from(target, begin, end); });
  } else {
    if (out.width != width || out.height != height) out.resize(width, height);
    merge(frame->delivered, frame->slot, out);
    if (aux) {
      if (gbuffer_.width != width || gbuffer_.height != height) gbuffer_.resize(width, height);
      for_band_rows(frame->delivered, frame->slot, [&](const BandBuffer& target, int begin, int end) {
        target.copy_aux_rows_to(gbuffer_, begin, end);
      });
    } else if (!gbuffer_.empty()) {
      gbuffer_.clear();
    }
  }
  merging.finish();
  stats.wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - frame->start).count();
}

FrameStats Renderer::wait_frame() {
  if (pending_.empty()) throw std::logic_error("Renderer::finish_frame: no frame was begun");
  if (unmerged_) throw std::logic_error("Renderer::wait_frame: the previous frame was not merged");
  std::unique_ptr<PendingFrame> frame = std::move(pending_.front());
  pending_.pop_front();
  FrameStats& stats = frame->stats;
  const BandJob& job = frame->job;
  // With two frames in flight a frame's bands start only when the frame before's have ended: its time
  // counts from then.
  const Clock::time_point counted_from =
      options_.frames_in_flight == 2 ? std::max(frame->start, last_round_end_) : frame->start;
  RoundResult first = collect(frame->assignments, frame->ids, counted_from + options_.frame_timeout, stats.stages);
  last_round_end_ = Clock::now();
  frame->delivered = first.delivered;
  last_measurements_.clear();
  for (int id : first.finished) {
    TracerFrameStats& t = stats.tracers[static_cast<size_t>(id)];
    t.ms = measured_ms(first.of(id));
    t.job_wait_ms = first.of(id).job_wait_ms;
    t.outcome = TracerOutcome::rendered;
    stats.frame_ms = std::max(stats.frame_ms, t.ms);
    last_measurements_.push_back({id, balance::Band{t.row_begin, t.row_end}, t.ms});
    if (t.ms > 0.0) workers_[static_cast<size_t>(id)]->rows_per_ms = (t.row_end - t.row_begin) / t.ms;
  }
  if (options_.frames_in_flight == 2 && !options_.use_reported_time) {
    // Frames overlap: a tracer is idle only while it has no job, from the end of its job before to the
    // start of this one (at most the time between the two frames' hand-outs), and busy for its band.
    for (int id : first.finished) {
      TracerFrameStats& t = stats.tracers[static_cast<size_t>(id)];
      const double waited = first.of(id).waited_ms;
      t.idle_ms = waited < 0.0 ? 0.0 : std::clamp(waited, 0.0, frame->since_previous_ms);
      stats.idle_ms += t.idle_ms;
      stats.summed_tracer_ms += t.idle_ms + t.ms;
    }
  } else {
    int taking_part = 0;
    for (TracerFrameStats& t : stats.tracers) {
      if (t.outcome == TracerOutcome::rendered) {
        t.idle_ms = stats.frame_ms - t.ms;
        stats.idle_ms += t.idle_ms;
        ++taking_part;
      }
    }
    stats.summed_tracer_ms = taking_part * stats.frame_ms;
  }
  stats.idle_percent = stats.summed_tracer_ms > 0.0 ? 100.0 * stats.idle_ms / stats.summed_tracer_ms : 0.0;

  // Re-render what the dropped tracers did not deliver, split among those that finished, in
  // proportion to the speed they just showed, until every row is covered or nobody is left.
  std::vector<balance::Band> missing;
  auto drop = [&](const std::vector<int>& ids, TracerOutcome why, const std::vector<balance::Band>& their_bands,
                  const RoundResult& round) {
    for (size_t i = 0; i < ids.size(); ++i) {
      TracerFrameStats& t = stats.tracers[static_cast<size_t>(ids[i])];
      if (t.outcome != TracerOutcome::threw && t.outcome != TracerOutcome::timed_out) ++stats.dropped;
      t.outcome = why;
      if (why == TracerOutcome::threw) t.error = round.of(ids[i]).error;
      missing.push_back(their_bands[i]);
      spdlog::warn("frame {}: tracer {} ({}) {} on rows [{}, {}){}{}; re-rendering them on the others", stats.frame,
                   t.id, t.name, why == TracerOutcome::threw ? "threw" : "timed out", their_bands[i].begin,
                   their_bands[i].end, t.error.empty() ? "" : ": ", t.error);
    }
  };
  auto band_of = [&](const std::vector<int>& ids) {
    std::vector<balance::Band> b;
    for (int id : ids) b.push_back({stats.tracers[static_cast<size_t>(id)].row_begin, stats.tracers[static_cast<size_t>(id)].row_end});
    return b;
  };
  drop(first.threw, TracerOutcome::threw, band_of(first.threw), first);
  drop(first.timed_out, TracerOutcome::timed_out, band_of(first.timed_out), first);

  std::vector<int> helpers = first.finished, needs_commits;
  if (!missing.empty()) {
    // Benched tracers that are done with their commits help too (with their probe, if any, harvested
    // first: a helper's job replaces its result). With nobody else left, they are waited for.
    Completion& completion = *workers_.front()->completion;
    std::unique_lock lock(completion.mutex);
    const auto deadline = Clock::now() + options_.frame_timeout;
    // One still on an earlier frame's side job missed this frame's commits: it gets them with its rows.
    for (const TracerFrameStats& t : stats.tracers) {
      Worker& w = *workers_[static_cast<size_t>(t.id)];
      const bool behind = t.outcome == TracerOutcome::busy && !w.side_jobs.empty();
      if (t.outcome != TracerOutcome::no_rows && !behind) continue;
      const auto side_jobs_ended = [&] {
        return std::all_of(w.side_jobs.begin(), w.side_jobs.end(), [&](const Worker::SideJob& j) { return w.ended(j.id); });
      };
      if (first.finished.empty() && !w.side_jobs.empty()) completion.cv.wait_until(lock, deadline, side_jobs_ended);
      // Busy also with the next frame's side job queued (two frames in flight): it does not help.
      if (w.busy()) continue;
      const bool side_job_failed = std::any_of(w.outcomes.begin(), w.outcomes.end(), [&](const Outcome& o) {
        return !o.ok && std::any_of(w.side_jobs.begin(), w.side_jobs.end(),
                                    [&](const Worker::SideJob& j) { return j.id == o.job_id; });
      });
      harvest_side_job(w, stats.stages);
      if (side_job_failed || !w.side_jobs.empty()) continue;
      helpers.push_back(t.id);
      if (behind) needs_commits.push_back(t.id);
    }
  }
  const auto recovery_start = Clock::now();
  while (!missing.empty()) {
    if (helpers.empty()) {
      throw std::runtime_error("frame " + std::to_string(stats.frame) + ": rows [" + std::to_string(missing.front().begin) + ", " +
                               std::to_string(missing.front().end) + ") could not be rendered: every tracer failed or timed out");
    }
    const balance::Band band = missing.back();
    missing.pop_back();
    std::vector<double> speeds;
    for (int id : helpers) {
      const double rows_per_ms = workers_[static_cast<size_t>(id)]->rows_per_ms;
      speeds.push_back(rows_per_ms > 0.0 ? rows_per_ms : 1.0);
    }
    std::vector<balance::Band> parts = balance::bands_from_shares(band.rows(), speeds);
    std::vector<Assignment> round;
    for (size_t i = 0; i < helpers.size(); ++i) {
      if (!parts[i].empty()) round.push_back({helpers[i], {band.begin + parts[i].begin, band.begin + parts[i].end}, false, {}});
    }
    // Helpers that have not had this frame's commits yet get them first (their assignments lead).
    std::stable_partition(round.begin(), round.end(), [&](const Assignment& a) {
      return std::find(needs_commits.begin(), needs_commits.end(), a.worker) != needs_commits.end();
    });
    const auto with_commits = std::find_if(round.begin(), round.end(), [&](const Assignment& a) {
      return std::find(needs_commits.begin(), needs_commits.end(), a.worker) == needs_commits.end();
    });
    std::vector<Assignment> first_part(round.begin(), with_commits), second_part(with_commits, round.end());
    std::vector<uint64_t> round_ids = assign(first_part, job, frame->slot, true);
    const std::vector<uint64_t> rest_ids = assign(second_part, job, frame->slot, false);
    round_ids.insert(round_ids.end(), rest_ids.begin(), rest_ids.end());
    round = first_part;  // with their due times
    round.insert(round.end(), second_part.begin(), second_part.end());
    for (const Assignment& a : first_part) std::erase(needs_commits, a.worker);
    const auto round_start = Clock::now();
    RoundResult r = collect(round, round_ids, round_start + options_.frame_timeout, stats.stages);
    frame->delivered.insert(frame->delivered.end(), r.delivered.begin(), r.delivered.end());
    for (const Assignment& a : round) {
      TracerFrameStats& t = stats.tracers[static_cast<size_t>(a.worker)];
      if (std::find(r.finished.begin(), r.finished.end(), a.worker) != r.finished.end()) {
        t.recovery_rows += a.band.rows();
        t.recovery_ms += measured_ms(r.of(a.worker));
      }
    }
    std::vector<int> failed = r.threw;
    failed.insert(failed.end(), r.timed_out.begin(), r.timed_out.end());
    std::vector<balance::Band> failed_bands;
    for (int id : failed) {
      for (const Assignment& a : round) {
        if (a.worker == id) failed_bands.push_back(a.band);
      }
      std::erase(helpers, id);
      std::erase_if(last_measurements_, [id](const balance::TracerMeasurement& m) { return m.tracer == id; });
    }
    std::vector<int> threw_ids = r.threw, late_ids = r.timed_out;
    drop(threw_ids, TracerOutcome::threw, std::vector<balance::Band>(failed_bands.begin(), failed_bands.begin() + static_cast<long>(threw_ids.size())), r);
    drop(late_ids, TracerOutcome::timed_out, std::vector<balance::Band>(failed_bands.begin() + static_cast<long>(threw_ids.size()), failed_bands.end()), r);
  }
  for (const TracerFrameStats& t : stats.tracers) stats.recovery_ms = std::max(stats.recovery_ms, t.recovery_ms);
  if (!options_.use_reported_time && stats.dropped > 0)
    stats.recovery_ms = std::chrono::duration<double, std::milli>(Clock::now() - recovery_start).count();
  stats.wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - frame->start).count();
  FrameStats result = std::move(stats);
  unmerged_ = std::move(frame);
  return result;
}

}  // namespace cohort::core
