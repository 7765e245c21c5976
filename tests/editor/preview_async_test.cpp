// The editor's preview renders off the UI thread (editor/preview_worker.h): painting and
// requesting a frame return while a frame renders, the newest request is the one shown
// (a superseded request is never rendered, yet its changes reach the renderer), an older
// frame finishing late is dropped, and strokes show coarse drafts, then the full grid.
//
// The renderers here are real CPU previews behind a gate the test opens: "returns while
// rendering" is checked as the worker's busy flag still being set when the call returns,
// not as a wall-clock race.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>

#include "edit_session_support.h"
#include "volume/core/error.h"
#include "volume/eval/image_metrics.h"

namespace sslpv::test {
namespace {

using namespace std::chrono_literals;

/// Holds renders until opened. A render that waited longer than kGiveUp proceeds and says
/// so: a preview that blocks the caller then fails the test instead of hanging it.
class Gate {
 public:
  static constexpr auto kGiveUp = 30s;
  void open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }
  /// Called by a render: counts it, then waits for open().
  void pass() {
    std::unique_lock<std::mutex> lock(mutex_);
    ++started_;
    changed_.notify_all();
    if (!changed_.wait_for(lock, kGiveUp, [&] { return open_; })) gaveUp_ = true;
  }
  /// Waits (bounded) until `n` renders have started.
  bool waitStarted(int n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, kGiveUp, [&] { return started_ >= n; });
  }
  int started() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return started_;
  }
  bool gaveUp() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return gaveUp_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool open_ = false;
  bool gaveUp_ = false;
  int started_ = 0;
};

/// The real CPU preview, each render held by the gate first.
class GatedRenderer final : public Renderer {
 public:
  GatedRenderer(std::unique_ptr<Renderer> inner, std::shared_ptr<Gate> gate)
      : inner_(std::move(inner)), gate_(std::move(gate)) {}
  Image render(const LpvSettings& settings, RenderReport* report) override {
    gate_->pass();
    return inner_->render(settings, report);
  }
  void setCamera(const Camera& camera) override { inner_->setCamera(camera); }
  void setLights(const std::vector<Light>& lights) override { inner_->setLights(lights); }
  void setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) override {
    inner_->setMaterialSet(std::move(set), touched);
  }
  void setTime(double t) override { inner_->setTime(t); }
  std::string name() const override { return inner_->name(); }

 private:
  std::unique_ptr<Renderer> inner_;
  std::shared_ptr<Gate> gate_;
};

/// Options whose renderers pass `gate` (only the `which`-th renderer built, 0 = the full
/// one, 1 = the draft one; -1: all).
PreviewOptions gatedPreview(std::shared_ptr<Gate> gate, int which = -1) {
  PreviewOptions options = smallPreview();
  auto built = std::make_shared<int>(0);
  options.makeRenderer = [gate, which, built](const Scene& scene, BackendKind backend) {
    std::unique_ptr<Renderer> inner = makeRenderer(scene, backend);
    const int index = (*built)++;
    if (which >= 0 && index != which) return inner;
    return std::unique_ptr<Renderer>(std::make_unique<GatedRenderer>(std::move(inner), gate));
  };
  return options;
}

/// The session's painted set written beside `f.scene` as `name`.vdb and a scene naming it.
fs::path exportedScene(const Files& f, const EditSession& s, const std::string& name) {
  s.exportMaterialSet(f.dir / (name + ".vdb"));
  ordered json = sceneJson();
  json["material"]["vdb"] = name + ".vdb";
  const fs::path scene = f.dir / (name + ".json");
  writeText(scene, json.dump());
  return scene;
}

TEST(PreviewAsync, StrokeAndRequestReturnWhileAFrameRenders) {
  // A frame is held in the renderer; painting a whole stroke and requesting the next frame
  // must return with that frame still rendering (the UI thread never waits for it), and
  // the stroke's frame follows once the first is let through.
  Files f;
  auto gate = std::make_shared<Gate>();
  EditSession s(f.scene, gatedPreview(gate));
  s.requestPreview(PreviewQuality::Full);
  ASSERT_TRUE(gate->waitStarted(1)) << "the first frame never started";

  const auto start = std::chrono::steady_clock::now();
  const StrokeResult stroke = s.applyStroke(darkStroke());
  const std::uint64_t serial = s.requestPreview(PreviewQuality::Full);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const bool stillRendering = s.previewBusy(PreviewQuality::Full) && gate->started() == 1 && !gate->gaveUp();
  EXPECT_TRUE(stillRendering) << "the stroke and the request returned only after the held frame (" << ms << " ms)";
  EXPECT_GT(stroke.voxelsChanged, 0u);
  EXPECT_FALSE(s.takePreview().has_value()) << "no frame can be finished yet";
  std::printf("[          ] stroke + request returned in %.2f ms while the first frame was held\n", ms);

  gate->open();
  const std::optional<PreviewFrame> frame = s.waitForPreview();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->serial, serial);
  EXPECT_TRUE(frame->error.empty()) << frame->error;
  EXPECT_LT(maxRelativeDifference(frame->image, freshRender(exportedScene(f, s, "painted"), s)), 1e-5);
}

TEST(PreviewAsync, TheLastRequestIsShownAndSupersededChangesStillArrive) {
  // While frame 1 is held: stroke A, request 2, a camera move, stroke B, request 3.
  // Request 2 is superseded before it starts, so only frames 1 and 3 render; frame 3 must
  // show both strokes from the moved camera (stroke A's region reached the renderer with
  // request 3), equal to a fresh full render of that state.
  Files f;
  auto gate = std::make_shared<Gate>();
  EditSession s(f.scene, gatedPreview(gate));
  s.requestPreview(PreviewQuality::Full);
  ASSERT_TRUE(gate->waitStarted(1));

  s.applyStroke(darkStroke(-3.0));
  s.requestPreview(PreviewQuality::Full);
  Camera side = s.previewCamera();
  side.position = glm::dvec3(-25.0, 5.0, 15.0);
  s.setPreviewCamera(side);
  s.applyStroke(darkStroke(2.0));
  const std::uint64_t last = s.requestPreview(PreviewQuality::Full);
  EXPECT_FALSE(s.previewStale());

  gate->open();
  const std::optional<PreviewFrame> frame = s.waitForPreview();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->serial, last);
  EXPECT_EQ(gate->started(), 2) << "the superseded request should never have rendered";
  EXPECT_FALSE(gate->gaveUp());
  EXPECT_LT(frame->report.resampledCells, frame->report.frame.cellCount()) << "strokes resample their regions only";
  EXPECT_LT(maxRelativeDifference(frame->image, freshRender(exportedScene(f, s, "both"), s)), 1e-5);
  EXPECT_FALSE(s.takePreview().has_value()) << "each frame is handed out once";
}

TEST(PreviewAsync, AnOlderFrameFinishingLateIsDropped) {
  // The draft renderer (the second one built) is held: its frame 1 finishes after the
  // full frame 2, and must not replace it on screen.
  ordered json = sceneJson();
  json["lpv"]["resolution"] = 24;
  Files f(json);
  auto gate = std::make_shared<Gate>();
  EditSession s(f.scene, gatedPreview(gate, 1));
  ASSERT_EQ(s.draftResolution(), kDraftPreviewResolution);
  s.applyStroke(darkStroke());
  const std::uint64_t draft = s.requestPreview(PreviewQuality::Draft);
  ASSERT_TRUE(gate->waitStarted(1));
  const std::uint64_t full = s.requestPreview(PreviewQuality::Full);
  ASSERT_GT(full, draft);

  std::optional<PreviewFrame> shown;
  for (auto until = std::chrono::steady_clock::now() + Gate::kGiveUp; !shown && std::chrono::steady_clock::now() < until;)
    if (!(shown = s.takePreview())) std::this_thread::sleep_for(5ms);
  ASSERT_TRUE(shown.has_value()) << "the full frame never arrived while the draft was held";
  EXPECT_EQ(shown->serial, full);
  EXPECT_FALSE(shown->draft);
  EXPECT_EQ(shown->resolution, 24);

  gate->open();
  EXPECT_FALSE(s.waitForPreview().has_value()) << "the late draft shows an older state than the frame on screen";
}

TEST(PreviewAsync, StrokesShowDraftsOnTheCoarseGridThenTheFullFrame) {
  // Grid 32: a draft is a 16³ frame of the current voxels (it changes as the stroke does)
  // at half the image size, a full frame is 32³; a full request also answers a pending
  // draft's staleness. At grid 16 a draft is a full frame.
  ordered json = sceneJson();
  json["lpv"]["resolution"] = 32;
  Files f(json);
  EditSession s(f.scene, smallPreview());
  const std::optional<PreviewFrame> none = s.waitForPreview();
  EXPECT_FALSE(none.has_value()) << "nothing was requested";
  const Image clean = s.renderPreview();

  const Stroke stroke = darkStroke();
  s.beginStroke(stroke.brush);
  s.addPoints(stroke.points);
  EXPECT_TRUE(s.previewStale(PreviewQuality::Draft));
  s.requestPreview(PreviewQuality::Draft);
  EXPECT_FALSE(s.previewStale(PreviewQuality::Draft));
  EXPECT_TRUE(s.previewStale(PreviewQuality::Full)) << "a draft leaves the full frame to do";
  std::optional<PreviewFrame> draft = s.waitForPreview();
  ASSERT_TRUE(draft.has_value());
  EXPECT_TRUE(draft->draft);
  EXPECT_EQ(draft->resolution, kDraftPreviewResolution);
  EXPECT_EQ(draft->report.frame.dims.x, kDraftPreviewResolution) << "the frame was not rendered on the draft grid";
  EXPECT_EQ(draft->image.width, (clean.width + 1) / 2) << "drafts are half the size each way";
  EXPECT_EQ(draft->image.height, std::max(16, (clean.height + 1) / 2));
  s.endStroke();

  s.requestPreview(PreviewQuality::Full);
  EXPECT_FALSE(s.previewStale(PreviewQuality::Draft));
  std::optional<PreviewFrame> full = s.waitForPreview();
  ASSERT_TRUE(full.has_value());
  EXPECT_FALSE(full->draft);
  EXPECT_EQ(full->resolution, 32);
  EXPECT_GT(maxRelativeDifference(full->image, clean), 0.05) << "the stroke must show in the full frame";
  EXPECT_GT(maxRelativeDifference(draft->image, clean), 0.05) << "the stroke must show in the draft";

  Files small;
  EditSession coarse(small.scene, smallPreview());
  EXPECT_EQ(coarse.draftResolution(), 16);
  coarse.requestPreview(PreviewQuality::Draft);
  const std::optional<PreviewFrame> same = coarse.waitForPreview();
  ASSERT_TRUE(same.has_value());
  EXPECT_FALSE(same->draft) << "at grid 16 a draft is the full frame";
  EXPECT_FALSE(coarse.previewStale(PreviewQuality::Full));
}

TEST(PreviewAsync, AFailedFrameReportsItsReasonAndTheNextFrameIsWhole) {
  // A renderer that throws once: the frame carries the reason (renderPreview rethrows it),
  // and the following frame, rebuilt from the whole newest state, equals a fresh render.
  Files f;
  auto failNext = std::make_shared<bool>(false);
  class Failing final : public Renderer {
   public:
    Failing(std::unique_ptr<Renderer> inner, std::shared_ptr<bool> fail)
        : inner_(std::move(inner)), fail_(std::move(fail)) {}
    Image render(const LpvSettings& settings, RenderReport* report) override {
      if (std::exchange(*fail_, false)) throw ResourceError("test: the preview ran out of memory");
      return inner_->render(settings, report);
    }
    void setCamera(const Camera& camera) override { inner_->setCamera(camera); }
    void setLights(const std::vector<Light>& lights) override { inner_->setLights(lights); }
    void setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) override {
      inner_->setMaterialSet(std::move(set), touched);
    }
    void setTime(double t) override { inner_->setTime(t); }
    std::string name() const override { return inner_->name(); }

   private:
    std::unique_ptr<Renderer> inner_;
    std::shared_ptr<bool> fail_;
  };
  PreviewOptions options = smallPreview();
  options.makeRenderer = [failNext](const Scene& scene, BackendKind backend) {
    return std::unique_ptr<Renderer>(std::make_unique<Failing>(makeRenderer(scene, backend), failNext));
  };
  EditSession s(f.scene, options);
  s.renderPreview();
  s.applyStroke(darkStroke());
  *failNext = true;  // read by the worker only after the request below hands it a job
  EXPECT_THROW(s.renderPreview(), ResourceError);
  s.applyStroke(darkStroke(-3.0));
  const Image image = s.renderPreview();
  EXPECT_LT(maxRelativeDifference(image, freshRender(exportedScene(f, s, "after"), s)), 1e-5);
}

}  // namespace
}  // namespace sslpv::test
