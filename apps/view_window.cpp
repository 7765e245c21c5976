#include "apps/view_window.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

#include "apps/cli_output.h"
#include "apps/view_controls.h"
#include "apps/view_overlay.h"
#include "apps/view_worker.h"
#include "backend/backends.h"
#include "gpu/vk/device.h"
#include "gpu/vk/presenter.h"
#include "volume/core/error.h"
#include "volume/core/image_io.h"

namespace sslpv {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Animation: a scene with deformers plays (the render thread's backend is posed at each new
// time, keeping its grid and warm light); a static scene's time keys (Space, Left, Right)
// do nothing.
bool sceneIsAnimated(const Scene& scene) { return scene.animated(); }

constexpr auto kPollInterval = std::chrono::milliseconds(500);  // how often the files' mtimes are read
constexpr auto kTitleInterval = std::chrono::milliseconds(250);
constexpr auto kFrameTimeout = std::chrono::minutes(10);       // --frames: one frame, however slow
constexpr auto kScriptWaitTimeout = std::chrono::seconds(120);  // --script: wait-reload(-failed)
constexpr int kDragSteps = 8;                                   // cursor moves of a scripted drag

std::string glfwLastError = "unknown GLFW error";
void onGlfwError(int /*code*/, const char* text) { glfwLastError = text ? text : "unknown GLFW error"; }

class GlfwSession {
 public:
  GlfwSession() {
    glfwSetErrorCallback(onGlfwError);
    if (!glfwInit())
      throw ResourceError("view: cannot open a window: " + glfwLastError +
                          " (no X display? run it under xvfb-run -a, or write images with `sslpv render`)");
  }
  ~GlfwSession() { glfwTerminate(); }
  GlfwSession(const GlfwSession&) = delete;
  GlfwSession& operator=(const GlfwSession&) = delete;
};

struct WindowDeleter {
  void operator()(GLFWwindow* window) const { glfwDestroyWindow(window); }
};

/// Made on the render thread: the backend the user chose (backend/backends.h), rendering
/// on the window's device. Under auto, a Vulkan backend that cannot run here is tried
/// once; the CPU backend renders from then on.
RendererFactory makeFactory(std::shared_ptr<Backends> backends) {
  return [backends](const Scene& scene) -> std::unique_ptr<Renderer> {
    const bool wasVulkan = backends->usesVulkan();
    std::unique_ptr<Renderer> renderer = backends->make(scene);
    if (wasVulkan && !backends->usesVulkan()) printWarning("view: " + backends->note());
    return renderer;
  };
}

struct FileStamp {
  bool exists = false;
  fs::file_time_type time{};
  std::uintmax_t size = 0;
  bool operator==(const FileStamp& o) const { return exists == o.exists && time == o.time && size == o.size; }
};

FileStamp stampOf(const fs::path& file) {
  std::error_code error;
  FileStamp stamp;
  stamp.time = fs::last_write_time(file, error);
  if (error) return stamp;
  stamp.size = fs::file_size(file, error);
  stamp.exists = !error;
  return stamp;
}

/// What a scene is read from: the JSON, its material set and its mesh file.
std::vector<fs::path> watchedFiles(const Scene& scene) {
  std::vector<fs::path> files{scene.file};
  if (scene.material.vdb) files.push_back(*scene.material.vdb);
  if (scene.mesh.kind == MeshSource::Kind::File) files.push_back(scene.mesh.path);
  return files;
}

std::string fixed1(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", v);
  return text;
}

std::string upper(std::string s) {
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

class Viewer {
 public:
  Viewer(const ViewArgs& args, ViewSetup& setup, GLFWwindow* window, gpu::SwapchainPresenter& presenter,
         RenderWorker& worker)
      : args_(args),
        script_(std::move(setup.script)),
        window_(window),
        presenter_(presenter),
        worker_(worker),
        controls_(setup.scene, setup.settings),
        overlay_(!args.noOverlay) {
    controls_.setAnimated(sceneIsAnimated(setup.scene));
    keepPresented_ = framesMode() || std::any_of(script_.begin(), script_.end(), [](const ScriptEvent& e) {
                       return e.kind == ScriptEvent::Kind::Screenshot;
                     });
    baseScene_ = std::make_shared<const Scene>(std::move(setup.scene));
    scene_ = baseScene_;
    watchFiles();
  }

  int run();

  // Input, from the window's callbacks and from scripts alike.
  void mouseButton(bool right, bool pressed, double x, double y);
  void cursor(double x, double y);
  void scroll(double steps);
  void key(ViewKey key, bool pressed);
  void redraw() { redraw_ = true; }
  /// The first frame's note says why it takes long on a Vulkan backend.
  void firstFrameCompilesPipelines(bool yes) { firstFrameCompiles_ = yes; }

 private:
  enum class Drag { None, Camera, Light };

  bool framesMode() const { return args_.frames > 0; }
  void watchFiles();
  void pollFiles(Clock::time_point now);
  void timeChanged();
  void requestFrame();
  void collectResults();
  void present();
  /// Before the first frame: a note with the seconds waited, redrawn a few times a second.
  void presentWaitingNote(Clock::time_point now);
  void applyScript(const ScriptEvent& event);
  void waitForScript(const ScriptEvent& event);
  std::vector<std::string> statusLines() const;
  void updateTitle();
  double fps() const;
  void printSummary() const;

  const ViewArgs& args_;
  std::vector<ScriptEvent> script_;
  GLFWwindow* window_;
  gpu::SwapchainPresenter& presenter_;
  RenderWorker& worker_;
  ViewControls controls_;

  std::shared_ptr<const Scene> baseScene_;  ///< as loaded from the file
  std::shared_ptr<const Scene> scene_;      ///< at the current animation time
  std::vector<std::pair<fs::path, FileStamp>> watched_;
  Clock::time_point lastPoll_ = Clock::now();

  int width_ = 0, height_ = 0;  ///< framebuffer size
  bool dirty_ = true, quit_ = false, overlay_ = true, redraw_ = true;
  Drag drag_ = Drag::None;
  bool lightKey_ = false;
  double lastX_ = 0, lastY_ = 0;
  std::uint64_t requested_ = 0, finished_ = 0;

  std::optional<RenderResult> frame_;  ///< the last good frame
  std::shared_ptr<const Scene> shownScene_;
  int reloadsShown_ = 0, reloadFailures_ = 0;
  std::deque<Clock::time_point> newFrames_;  ///< when recent new frames were presented (fps)
  bool newFrame_ = false;
  Clock::time_point lastTitle_{};
  Clock::time_point opened_ = Clock::now(), lastNote_{};
  bool firstFrameCompiles_ = false;

  // --frames statistics.
  int presented_ = 0;
  Clock::time_point firstPresent_{}, lastPresent_{};
  gpu::DisplayFrame lastPresented_;
  bool keepPresented_ = false;  ///< read each presented frame back (screenshots need it)
  int rendered_ = 0;
  StageTimes stageSum_;
  double wallSum_ = 0.0;
  double presentMs_ = 0.0;  ///< overlay, copy into the swapchain and present, all frames
  int stepsLast_ = 0;
};

void Viewer::watchFiles() {
  watched_.clear();
  for (const fs::path& file : watchedFiles(*baseScene_)) watched_.emplace_back(file, stampOf(file));
}

void Viewer::pollFiles(Clock::time_point now) {
  if (now - lastPoll_ < kPollInterval) return;
  lastPoll_ = now;
  bool changed = false;
  for (auto& [file, stamp] : watched_) {
    const FileStamp current = stampOf(file);
    changed = changed || !(current == stamp);
    stamp = current;
  }
  if (!changed) return;
  try {
    Scene scene = loadScene(args_.scene);
    controls_.sceneChanged(scene);
    controls_.setAnimated(sceneIsAnimated(scene));
    baseScene_ = std::make_shared<const Scene>(std::move(scene));
    watchFiles();
    timeChanged();
  } catch (const InputError& e) {
    // A half-saved file included: the next change on disk tries again.
    ++reloadFailures_;
    printWarning(std::string("view: ") + e.what() + " (the window keeps the last good frame)");
  }
}

void Viewer::timeChanged() {
  scene_ = baseScene_;
  dirty_ = true;
}

void Viewer::requestFrame() {
  RenderRequest request;
  request.scene = scene_;
  request.camera = controls_.camera(width_, height_);
  request.lights = controls_.lights();
  request.settings = controls_.settings();
  request.exposure = args_.exposure;
  if (controls_.animated()) request.time = controls_.time();
  requested_ = worker_.request(std::move(request));
  dirty_ = false;
}

void Viewer::collectResults() {
  for (RenderResult& result : worker_.take()) {
    finished_ = std::max(finished_, result.id);
    if (!result.error.empty()) {
      if (!frame_ && result.resourceError) throw ResourceError(result.error);  // nothing shown: nothing to keep
      if (!frame_) throw InputError(result.error);
      if (result.scene != shownScene_) ++reloadFailures_;
      printWarning("view: " + result.error + " (the window keeps the last good frame)");
      continue;
    }
    if (shownScene_ && result.scene != shownScene_) ++reloadsShown_;
    shownScene_ = result.scene;
    if (rendered_ > 0) {  // the first frame also loads and voxelizes: not a typical frame
      const StageTimes& t = result.report.times;
      stageSum_.shadowMap += t.shadowMap;
      stageSum_.injection += t.injection;
      stageSum_.propagation += t.propagation;
      stageSum_.shading += t.shading;
      wallSum_ += result.wallMs;
    }
    ++rendered_;
    frame_ = std::move(result);
    newFrame_ = true;
    redraw_ = true;
  }
}

std::vector<std::string> Viewer::statusLines() const {
  const RenderReport& report = frame_->report;
  const StageTimes& t = report.times;
  auto stage = [&](Stage s, double ms) { return t.cached(s) ? std::string("-") : fixed1(ms); };
  const std::string backend = report.backend.substr(0, report.backend.find(' '));
  const LpvSettings& s = frame_->settings;
  const std::string steps = s.autoSteps ? "AUTO (" + std::to_string(report.propagation.stepsRun) + ")"
                                        : std::to_string(report.propagation.stepsRun);
  const std::string time = controls_.animated()
                               ? "T " + fixed1(controls_.time()) + (controls_.playing() ? " PLAYING" : " PAUSED")
                               : "STATIC";
  return {upper(backend) + " " + std::to_string(s.resolution) + "^3 STEPS " + steps,
          "SHADOW " + stage(Stage::ShadowMap, t.shadowMap) + " INJECT " + stage(Stage::Injection, t.injection) +
              " MS",
          "PROPAGATE " + stage(Stage::Propagation, t.propagation) + " SHADE " + stage(Stage::Shading, t.shading) +
              " MS",
          fixed1(fps()) + " FPS  " + time};
}

double Viewer::fps() const {
  // Idle for a second: no frames are being made, whatever the last burst's rate was.
  if (newFrames_.size() < 2 || Clock::now() - newFrames_.back() > std::chrono::seconds(1)) return 0.0;
  const double seconds = std::chrono::duration<double>(newFrames_.back() - newFrames_.front()).count();
  return seconds > 0.0 ? double(newFrames_.size() - 1) / seconds : 0.0;
}

void Viewer::updateTitle() {
  std::string title = "sslpv view " + fs::path(args_.scene).filename().string();
  if (frame_) {
    std::string status;
    for (const std::string& line : statusLines()) status += " | " + line;
    title += status;
  }
  glfwSetWindowTitle(window_, title.c_str());
  lastTitle_ = Clock::now();
}

void Viewer::present() {
  if (!frame_) return;
  const Clock::time_point begin = Clock::now();
  if (newFrame_) {  // counted before the overlay is drawn, so it includes this frame
    newFrames_.push_back(begin);
    while (newFrames_.size() > 2 && begin - newFrames_.front() > std::chrono::seconds(1)) newFrames_.pop_front();
    newFrame_ = false;
  }
  gpu::DisplayFrame shown{frame_->width, frame_->height, frame_->rgb};
  if (overlay_) drawOverlay(shown.rgb, shown.width, shown.height, statusLines());
  const bool presented = presenter_.present(shown, width_, height_, keepPresented_ ? &lastPresented_ : nullptr);
  presentMs_ += std::chrono::duration<double, std::milli>(Clock::now() - begin).count();
  redraw_ = false;
  if (!presented) return;
  const Clock::time_point now = Clock::now();
  if (presented_ == 0) firstPresent_ = now;
  lastPresent_ = now;
  ++presented_;
}

void Viewer::presentWaitingNote(Clock::time_point now) {
  if (width_ <= 0 || height_ <= 0 || now - lastNote_ < std::chrono::milliseconds(200)) return;
  lastNote_ = now;
  std::vector<std::string> lines{"PREPARING THE FIRST FRAME " +
                                 fixed1(std::chrono::duration<double>(now - opened_).count()) + " S"};
  if (firstFrameCompiles_) lines.push_back("(VULKAN COMPILES ITS PIPELINES ONCE; LATER RUNS READ THE SHADER CACHE)");
  const gpu::DisplayFrame note{width_, height_, noteFrame(width_, height_, lines)};
  // Not counted as a presented frame: scripts and --frames count images of the scene.
  presenter_.present(note, width_, height_);
}

void Viewer::mouseButton(bool right, bool pressed, double x, double y) {
  drag_ = !pressed ? Drag::None : (right || lightKey_) ? Drag::Light : Drag::Camera;
  lastX_ = x;
  lastY_ = y;
}

void Viewer::cursor(double x, double y) {
  const double dx = x - lastX_, dy = y - lastY_;
  lastX_ = x;
  lastY_ = y;
  if (drag_ == Drag::Camera) controls_.orbitCamera(dx, dy);
  if (drag_ == Drag::Light) controls_.moveLight(dx, dy);
  if (drag_ != Drag::None) dirty_ = true;
}

void Viewer::scroll(double steps) {
  controls_.zoom(steps);
  dirty_ = true;
}

void Viewer::key(ViewKey key, bool pressed) {
  if (key == ViewKey::LightDrag) {
    lightKey_ = pressed;
    return;
  }
  if (!pressed) return;
  switch (key) {
    case ViewKey::Quit: quit_ = true; break;
    case ViewKey::Grid: controls_.cycleGrid(); dirty_ = true; break;
    case ViewKey::Steps: controls_.cycleSteps(); dirty_ = true; break;
    // A new scene object: the render thread builds the backend again, every stage cold.
    case ViewKey::Rerender: scene_ = std::make_shared<const Scene>(*scene_); dirty_ = true; break;
    case ViewKey::Overlay: overlay_ = !overlay_; redraw_ = true; break;
    case ViewKey::PlayPause: controls_.togglePlay(); redraw_ = true; break;
    case ViewKey::ScrubBack:
    case ViewKey::ScrubForward:
      if (controls_.animated()) {
        controls_.scrub(key == ViewKey::ScrubBack ? -1.0 : 1.0);
        timeChanged();
      }
      break;
    case ViewKey::LightDrag: break;
  }
}

void Viewer::applyScript(const ScriptEvent& e) {
  switch (e.kind) {
    case ScriptEvent::Kind::Drag:
      cursor(e.x0, e.y0);
      mouseButton(e.rightButton, true, e.x0, e.y0);
      for (int i = 1; i <= kDragSteps; ++i)
        cursor(e.x0 + (e.x1 - e.x0) * i / kDragSteps, e.y0 + (e.y1 - e.y0) * i / kDragSteps);
      mouseButton(e.rightButton, false, e.x1, e.y1);
      break;
    case ScriptEvent::Kind::Wheel: scroll(e.wheel); break;
    case ScriptEvent::Kind::Key:
      key(e.key, true);
      key(e.key, false);
      break;
    case ScriptEvent::Kind::Screenshot:
      if (lastPresented_.rgb.empty())
        throw InputError("--script: " + args_.script + ":" + std::to_string(e.line) +
                         ": screenshot before any frame was presented (use frame 1 or later)");
      writeDisplayPng(lastPresented_.rgb, lastPresented_.width, lastPresented_.height, e.file);
      break;
    case ScriptEvent::Kind::WaitReload:
    case ScriptEvent::Kind::WaitReloadFailed: waitForScript(e); break;
    case ScriptEvent::Kind::Resize: {
      glfwSetWindowSize(window_, e.width, e.height);
      // The X server resizes asynchronously; the main loop picks the new size up.
      const Clock::time_point deadline = Clock::now() + std::chrono::seconds(10);
      int w = 0, h = 0;
      do {
        glfwWaitEventsTimeout(0.01);
        glfwGetFramebufferSize(window_, &w, &h);
      } while ((w != e.width || h != e.height) && Clock::now() < deadline);
      break;
    }
  }
}

void Viewer::waitForScript(const ScriptEvent& e) {
  const bool failure = e.kind == ScriptEvent::Kind::WaitReloadFailed;
  const int before = failure ? reloadFailures_ : reloadsShown_;
  const Clock::time_point deadline = Clock::now() + kScriptWaitTimeout;
  while ((failure ? reloadFailures_ : reloadsShown_) == before) {
    if (Clock::now() > deadline)
      throw InputError("--script: " + args_.script + ":" + std::to_string(e.line) + ": no scene " +
                       (failure ? "reload failed" : "reload was shown") + " within 120 s");
    glfwPollEvents();
    pollFiles(Clock::now());
    if (dirty_) requestFrame();
    worker_.waitFor(requested_, std::chrono::milliseconds(50));
    collectResults();
  }
}

void Viewer::printSummary() const {
  const double seconds = std::chrono::duration<double>(lastPresent_ - firstPresent_).count();
  const int later = rendered_ - 1;
  char text[512];
  std::snprintf(text, sizeof text,
                "view: %d frames presented (%d rendered) at %dx%d, %s, %s: %.2f frames/s after the first; "
                "per rendered frame after the first: %.1f ms (shadow %.2f, inject %.2f, propagate %.2f, shade "
                "%.2f ms); presenting: %.1f ms per frame\n",
                presented_, rendered_, width_, height_, frame_ ? frame_->report.backend.c_str() : "no frame",
                controls_.settingsText().c_str(), seconds > 0.0 ? (presented_ - 1) / seconds : 0.0,
                later > 0 ? wallSum_ / later : 0.0, later > 0 ? stageSum_.shadowMap / later : 0.0,
                later > 0 ? stageSum_.injection / later : 0.0, later > 0 ? stageSum_.propagation / later : 0.0,
                later > 0 ? stageSum_.shading / later : 0.0, presented_ > 0 ? presentMs_ / presented_ : 0.0);
  std::cout << text << std::flush;
}

int Viewer::run() {
  const auto start = CliClock::now();
  glfwGetFramebufferSize(window_, &width_, &height_);
  Clock::time_point last = Clock::now();
  std::size_t next = 0;
  while (!quit_) {
    // Scripts run in the interactive loop too (frames count presents there as well).
    while (next < script_.size() && script_[next].frame <= presented_) applyScript(script_[next++]);
    if (framesMode()) {
      if (presented_ > 0 && args_.turntableDeg != 0.0) {
        controls_.orbitDegrees(args_.turntableDeg);
        dirty_ = true;
      }
      glfwPollEvents();
    } else {
      // Short waits while a frame renders (its result is collected promptly), long ones idle.
      glfwWaitEventsTimeout(finished_ < requested_ ? 0.005 : 0.05);
    }
    if (glfwWindowShouldClose(window_) || quit_) break;
    const Clock::time_point now = Clock::now();
    if (controls_.tick(std::chrono::duration<double>(now - last).count())) timeChanged();
    last = now;
    pollFiles(now);
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    if (w != width_ || h != height_) {
      width_ = w;
      height_ = h;
      dirty_ = w > 0 && h > 0;
    }
    if (!framesMode() && args_.turntableDeg != 0.0 && finished_ >= requested_) {
      controls_.orbitDegrees(args_.turntableDeg);
      dirty_ = true;
    }
    if (dirty_ && width_ > 0 && height_ > 0) requestFrame();
    if (framesMode() && !worker_.waitFor(requested_, kFrameTimeout))
      throw ResourceError("view: a frame took longer than 10 minutes to render");
    collectResults();
    if (framesMode() || redraw_) present();
    if (!frame_ && !framesMode()) presentWaitingNote(Clock::now());
    if (Clock::now() - lastTitle_ > kTitleInterval) updateTitle();
    if (framesMode() && presented_ >= args_.frames) break;
  }
  if (framesMode()) {
    printSummary();
    if (!args_.screenshot.empty()) {
      writeDisplayPng(lastPresented_.rgb, lastPresented_.width, lastPresented_.height, args_.screenshot);
      printWrote(args_.screenshot, std::to_string(lastPresented_.width) + "x" + std::to_string(lastPresented_.height),
                 start);
    }
  }
  return 0;
}

Viewer* viewerOf(GLFWwindow* window) { return static_cast<Viewer*>(glfwGetWindowUserPointer(window)); }

void installCallbacks(GLFWwindow* window, Viewer* viewer) {
  glfwSetWindowUserPointer(window, viewer);
  glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int /*mods*/) {
    if (button != GLFW_MOUSE_BUTTON_LEFT && button != GLFW_MOUSE_BUTTON_RIGHT) return;
    double x = 0, y = 0;
    glfwGetCursorPos(w, &x, &y);
    viewerOf(w)->mouseButton(button == GLFW_MOUSE_BUTTON_RIGHT, action == GLFW_PRESS, x, y);
  });
  // Exposed again after being covered: without a compositor the window must repaint.
  glfwSetWindowRefreshCallback(window, [](GLFWwindow* w) { viewerOf(w)->redraw(); });
  glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) { viewerOf(w)->cursor(x, y); });
  glfwSetScrollCallback(window, [](GLFWwindow* w, double /*dx*/, double dy) { viewerOf(w)->scroll(dy); });
  glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int /*scancode*/, int action, int /*mods*/) {
    const bool pressed = action != GLFW_RELEASE;
    const bool repeat = action == GLFW_REPEAT;
    Viewer* target = viewerOf(w);
    switch (key) {
      case GLFW_KEY_ESCAPE:
      case GLFW_KEY_Q: if (!repeat) target->key(ViewKey::Quit, pressed); break;
      case GLFW_KEY_G: if (!repeat) target->key(ViewKey::Grid, pressed); break;
      case GLFW_KEY_S: if (!repeat) target->key(ViewKey::Steps, pressed); break;
      case GLFW_KEY_R: if (!repeat) target->key(ViewKey::Rerender, pressed); break;
      case GLFW_KEY_H: if (!repeat) target->key(ViewKey::Overlay, pressed); break;
      case GLFW_KEY_L: target->key(ViewKey::LightDrag, pressed); break;
      case GLFW_KEY_SPACE: if (!repeat) target->key(ViewKey::PlayPause, pressed); break;
      case GLFW_KEY_LEFT: target->key(ViewKey::ScrubBack, pressed); break;
      case GLFW_KEY_RIGHT: target->key(ViewKey::ScrubForward, pressed); break;
      default: break;
    }
  });
}

}  // namespace

int runViewWindow(const ViewArgs& args, ViewSetup setup) {
  GlfwSession glfw;
  if (!glfwVulkanSupported())
    throw ResourceError("view: GLFW finds no Vulkan loader to present with (install libvulkan1 and "
                        "mesa-vulkan-drivers); `sslpv render` writes images without a window");
  gpu::DeviceOptions options;
  std::uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  if (!names)
    throw ResourceError("view: Vulkan cannot present to this display's windows (" + glfwLastError +
                        "); `sslpv render` writes images without a window");
  options.instanceExtensions.assign(names, names + count);
  options.swapchain = true;

  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  const std::string title = "sslpv view " + fs::path(args.scene).filename().string();
  std::unique_ptr<GLFWwindow, WindowDeleter> window(
      glfwCreateWindow(setup.width, setup.height, title.c_str(), nullptr, nullptr));
  if (!window) throw ResourceError("view: cannot create a " + std::to_string(setup.width) + "x" +
                                   std::to_string(setup.height) + " window: " + glfwLastError);

  std::unique_ptr<gpu::VulkanDevice> device;
  std::unique_ptr<gpu::SwapchainPresenter> presenter;
  try {
    device = std::make_unique<gpu::VulkanDevice>(options);
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    const VkResult made = glfwCreateWindowSurface(device->instance(), window.get(), nullptr, &surface);
    if (made != VK_SUCCESS)
      throw GpuError("glfwCreateWindowSurface failed: " + gpu::resultName(made) + " (" + glfwLastError + ")");
    int w = 0, h = 0;
    glfwGetFramebufferSize(window.get(), &w, &h);
    presenter = std::make_unique<gpu::SwapchainPresenter>(*device, surface, w, h);
  } catch (const GpuError& e) {
    throw ResourceError(std::string("view: cannot present the window with Vulkan: ") + e.what() +
                        "; `sslpv render` writes images without a window");
  }
  // Declared after the device and presenter, so it stops (and drops its backend) first.
  auto backends = std::make_shared<Backends>(parseBackendKind(args.backend), *device);
  const bool vulkanFrames = backends->usesVulkan();
  RenderWorker worker(makeFactory(std::move(backends)));
  Viewer viewer(args, setup, window.get(), *presenter, worker);
  viewer.firstFrameCompilesPipelines(vulkanFrames);
  installCallbacks(window.get(), &viewer);
  const int code = viewer.run();
  glfwSetWindowUserPointer(window.get(), nullptr);
  return code;
}

}  // namespace sslpv
