#pragma once
// One preview renderer on a thread of its own, so that the editor's UI thread never waits
// for a frame. The UI thread submits a job (a copy of what changed) and later takes the
// finished frame; a job not yet started is replaced by a newer one, so the worker never
// works through a queue of stale states. A render in progress runs to its end: neither
// backend can stop a frame half way, and a newer job starts right after it.
//
// Threads: after construction the renderer is used by the worker thread only; jobs
// carry immutable snapshots (never the set the brush engine paints in place), and the
// hand-over slots are guarded by one mutex.
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "editor/edit_session.h"

namespace sslpv {

/// What the renderer needs for one frame, all of it owned by the job.
struct PreviewJob {
  std::uint64_t serial = 0;
  /// A snapshot of the painted set; null: the renderer's set is still current.
  std::shared_ptr<const MaterialSet> set;
  bool wholeSet = false;          ///< with `set`: resample every cell, not only `touched`
  std::optional<Bounds> touched;  ///< with `set`: the world region changed since the renderer's set
  std::optional<Camera> camera;   ///< null: unchanged
  LpvSettings settings;
  bool draft = false;
};

class PreviewWorker {
 public:
  explicit PreviewWorker(std::unique_ptr<Renderer> renderer);
  /// Lets a render in progress finish, drops a pending job.
  ~PreviewWorker();
  PreviewWorker(const PreviewWorker&) = delete;
  PreviewWorker& operator=(const PreviewWorker&) = delete;

  /// Never waits for a render. A pending job is superseded; what it changed (region,
  /// camera) still reaches the renderer with `job`.
  void submit(PreviewJob job);
  /// A job is pending or rendering.
  bool busy() const;
  /// The last finished frame, once (then empty until the next one finishes).
  std::optional<PreviewFrame> take();
  /// Waits until no job is pending or rendering, then take().
  std::optional<PreviewFrame> wait();
  /// Frames rendered so far (a superseded job is never rendered).
  std::uint64_t framesRendered() const;

 private:
  void run();
  PreviewFrame render(PreviewJob& job);

  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::optional<PreviewJob> pending_;
  std::optional<PreviewFrame> finished_;
  bool rendering_ = false;
  bool stop_ = false;
  std::uint64_t rendered_ = 0;

  // Worker thread only.
  std::unique_ptr<Renderer> renderer_;
  /// The newest set and camera jobs carried: after a frame failed half way, the renderer
  /// gets them whole.
  std::shared_ptr<const MaterialSet> lastSet_;
  std::optional<Camera> lastCamera_;
  bool resendAll_ = false;

  std::thread thread_;  ///< last: starts once everything above exists
};

}  // namespace sslpv
