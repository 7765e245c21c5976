#include "editor/preview_worker.h"

#include <exception>
#include <utility>

namespace sslpv {

PreviewWorker::PreviewWorker(std::unique_ptr<Renderer> renderer)
    : renderer_(std::move(renderer)), thread_([this] { run(); }) {}

PreviewWorker::~PreviewWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    pending_.reset();
  }
  wake_.notify_all();
  thread_.join();
}

void PreviewWorker::submit(PreviewJob job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (pending_) {
      // The superseded job's snapshot is no newer than `job`'s (or is the current one when
      // `job` carries none), but its region and camera have not reached the renderer yet.
      PreviewJob& old = *pending_;
      if (!job.set) job.set = std::move(old.set);
      job.wholeSet = job.wholeSet || old.wholeSet;
      if (old.touched && !old.touched->empty()) {
        if (!job.touched) {
          job.touched = old.touched;
        } else {
          job.touched->extend(old.touched->min);
          job.touched->extend(old.touched->max);
        }
      }
      if (!job.camera) job.camera = old.camera;
    }
    pending_ = std::move(job);
  }
  wake_.notify_one();
}

bool PreviewWorker::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return pending_.has_value() || rendering_;
}

std::optional<PreviewFrame> PreviewWorker::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(finished_, std::nullopt);
}

std::optional<PreviewFrame> PreviewWorker::wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [&] { return !pending_ && !rendering_; });
  return std::exchange(finished_, std::nullopt);
}

std::uint64_t PreviewWorker::framesRendered() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rendered_;
}

void PreviewWorker::run() {
  for (;;) {
    PreviewJob job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
      if (stop_) return;
      job = std::move(*pending_);
      pending_.reset();
      rendering_ = true;
    }
    PreviewFrame frame = render(job);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_ = std::move(frame);
      rendering_ = false;
      ++rendered_;
    }
    idle_.notify_all();
  }
}

PreviewFrame PreviewWorker::render(PreviewJob& job) {
  PreviewFrame frame;
  frame.serial = job.serial;
  frame.draft = job.draft;
  frame.resolution = job.settings.resolution;
  const auto start = std::chrono::steady_clock::now();
  if (job.set) lastSet_ = job.set;
  if (job.camera) lastCamera_ = job.camera;
  try {
    if (resendAll_) {
      if (lastCamera_) renderer_->setCamera(*lastCamera_);
      if (lastSet_) renderer_->setMaterialSet(lastSet_, std::nullopt);
      resendAll_ = false;
    } else {
      if (job.camera) renderer_->setCamera(*job.camera);
      if (job.set) renderer_->setMaterialSet(job.set, job.wholeSet ? std::nullopt : job.touched);
    }
    frame.image = renderer_->render(job.settings, &frame.report);
  } catch (const std::exception& e) {
    frame.error = e.what();
    frame.failure = std::current_exception();
    // Where the failure left the renderer is unknown: the next frame starts from the whole
    // newest state.
    resendAll_ = true;
  } catch (...) {
    frame.error = "the preview renderer failed with an unknown error";
    frame.failure = std::current_exception();
    resendAll_ = true;
  }
  frame.finished = std::chrono::steady_clock::now();
  frame.renderMs = std::chrono::duration<double, std::milli>(frame.finished - start).count();
  return frame;
}

}  // namespace sslpv
