#pragma once
// The viewer's render thread: the window thread hands it the newest request and never
// waits for it; a request that was not started yet is replaced by a newer one, so at
// most one frame is ever queued and the window always shows the last finished frame.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "volume/lpv/frame_report.h"
#include "volume/core/image_io.h"
#include "volume/lpv/renderer.h"
#include "volume/scene/scene.h"

namespace sslpv {

/// Builds a backend for a scene; throws (InputError, GpuError, ...) when it cannot.
using RendererFactory = std::function<std::unique_ptr<Renderer>(const Scene&)>;

struct RenderRequest {
  /// A new pointer (a reload) builds a new backend; the same one reuses the cached stages.
  std::shared_ptr<const Scene> scene;
  /// The deformers' time (unset: the scene's own); a new time re-poses the same backend.
  std::optional<double> time;
  Camera camera;
  std::vector<Light> lights;
  LpvSettings settings;
  float exposure = 1.0f;
};

struct RenderResult {
  std::uint64_t id = 0;
  std::shared_ptr<const Scene> scene;
  LpvSettings settings;
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;  ///< toDisplayRgb8 of the frame; empty when it failed
  RenderReport report;
  double wallMs = 0.0;  ///< the frame as the render thread saw it, tone mapping included
  /// Why there is no frame: the request's scene could not be loaded (the last good
  /// backend stays in use) or the render failed. One line.
  std::string error;
  bool resourceError = false;  ///< the machine lacks what the backend needs (not the scene's fault)
};

class RenderWorker {
 public:
  explicit RenderWorker(RendererFactory factory);
  ~RenderWorker();  ///< lets a running frame finish, then stops
  RenderWorker(const RenderWorker&) = delete;
  RenderWorker& operator=(const RenderWorker&) = delete;

  /// Queues `request` in place of any request not yet started; returns its id (ids grow).
  std::uint64_t request(RenderRequest request);
  /// The results finished since the last call, oldest first (errors are never dropped).
  std::vector<RenderResult> take();
  /// Waits until the result of request `id` (or of a newer one) is finished; false on timeout.
  bool waitFor(std::uint64_t id, std::chrono::milliseconds timeout);

 private:
  void run();
  RenderResult renderOne(std::uint64_t id, const RenderRequest& request);

  RendererFactory factory_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<RenderRequest> pending_;
  std::uint64_t pendingId_ = 0, nextId_ = 1, finishedId_ = 0;
  std::vector<RenderResult> finished_;
  bool stop_ = false;

  // Owned by the render thread.
  std::unique_ptr<Renderer> renderer_;
  std::shared_ptr<const Scene> rendererScene_, failedScene_;
  std::optional<Camera> camera_;
  std::optional<std::vector<Light>> lights_;
  std::optional<double> time_;

  std::thread thread_;  // last: started once everything above exists
};

}  // namespace sslpv
