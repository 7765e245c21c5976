#include "apps/view_worker.h"

#include <new>
#include <utility>

#include "volume/core/error.h"

namespace sslpv {

namespace {

bool sameCamera(const Camera& a, const Camera& b) {
  return a.position == b.position && a.target == b.target && a.up == b.up && a.fovYDeg == b.fovYDeg &&
         a.width == b.width && a.height == b.height;
}

bool sameLights(const std::vector<Light>& a, const std::vector<Light>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].type != b[i].type || a[i].position != b[i].position || a[i].direction != b[i].direction ||
        a[i].fovDeg != b[i].fovDeg || a[i].intensity != b[i].intensity || a[i].irradiance != b[i].irradiance)
      return false;
  return true;
}

std::string oneLine(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  return text;
}

}  // namespace

RenderWorker::RenderWorker(RendererFactory factory) : factory_(std::move(factory)), thread_([this] { run(); }) {}

RenderWorker::~RenderWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

std::uint64_t RenderWorker::request(RenderRequest request) {
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    id = nextId_++;
    pending_ = std::move(request);
    pendingId_ = id;
  }
  changed_.notify_all();
  return id;
}

std::vector<RenderResult> RenderWorker::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(finished_, {});
}

bool RenderWorker::waitFor(std::uint64_t id, std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] { return finishedId_ >= id; });
}

void RenderWorker::run() {
  for (;;) {
    RenderRequest request;
    std::uint64_t id = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return stop_ || pending_.has_value(); });
      if (stop_) return;
      request = std::move(*pending_);
      pending_.reset();
      id = pendingId_;
    }
    RenderResult result = renderOne(id, request);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_.push_back(std::move(result));
      finishedId_ = id;
    }
    changed_.notify_all();
  }
}

RenderResult RenderWorker::renderOne(std::uint64_t id, const RenderRequest& request) {
  RenderResult result;
  result.id = id;
  result.settings = request.settings;
  const auto start = std::chrono::steady_clock::now();
  try {
    if (request.scene != rendererScene_ && request.scene != failedScene_) {
      try {
        renderer_ = factory_(*request.scene);
        rendererScene_ = request.scene;
        camera_.reset();
        lights_.reset();
        time_.reset();
      } catch (const std::bad_alloc&) {
        throw;
      } catch (const std::exception& e) {
        // The last good backend (if any) keeps rendering the camera and light moves.
        failedScene_ = request.scene;
        result.scene = request.scene;
        result.error = oneLine(e.what());
        result.resourceError = dynamic_cast<const ResourceError*>(&e) != nullptr;
        return result;
      }
    }
    result.scene = rendererScene_;
    if (!renderer_) {
      result.error = "no scene loaded";
      return result;
    }
    if (!camera_ || !sameCamera(*camera_, request.camera)) {
      renderer_->setCamera(request.camera);
      camera_ = request.camera;
    }
    if (!lights_ || !sameLights(*lights_, request.lights)) {
      renderer_->setLights(request.lights);
      lights_ = request.lights;
    }
    if (request.time && time_ != request.time) {
      renderer_->setTime(*request.time);
      time_ = request.time;
    }
    const Image image = renderer_->render(request.settings, &result.report);
    result.width = image.width;
    result.height = image.height;
    result.rgb = toDisplayRgb8(image, request.exposure);
  } catch (const std::bad_alloc&) {
    result.error = "out of memory rendering the frame (try a smaller --grid or window)";
    result.resourceError = true;
  } catch (const ResourceError& e) {
    result.error = oneLine(e.what());
    result.resourceError = true;
  } catch (const std::exception& e) {
    result.error = oneLine(e.what());
  }
  result.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace sslpv
