#include "editor/edit_session.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <fstream>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "editor/preview_worker.h"
#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene_file_edit.h"
#include "volume/core/strict_json.h"

namespace sslpv {
namespace fs = std::filesystem;

namespace {

constexpr const char* kCreator = "sslpv edit";
/// Sets these tools write are painted output: saving over one needs no confirmation.
constexpr const char* kPaintedCreators[] = {kCreator, "sslpv paint"};
constexpr int kMinPreviewSide = 16;

fs::path recoveryPathFor(const fs::path& sceneFile) {
  fs::path p = sceneFile;
  p += ".recovery.vdb";
  return p;
}

std::string readFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read the file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(file.string() + ": cannot read the file");
  return text.str();
}

/// Whether two cameras frame the same view (the window's camera round-trips through
/// VTK's doubles, so equal means equal to 1e-9 of the values).
bool sameView(const Camera& a, const Camera& b) {
  auto near = [](const glm::dvec3& x, const glm::dvec3& y) {
    return glm::length(x - y) <= 1e-9 * std::max({1.0, glm::length(x), glm::length(y)});
  };
  return near(a.position, b.position) && near(a.target, b.target) &&
         near(glm::normalize(a.up), glm::normalize(b.up)) && std::abs(a.fovYDeg - b.fovYDeg) <= 1e-9 * b.fovYDeg;
}

std::string jsonVec3(const glm::dvec3& v) {
  return "[" + formatNumber(v.x) + ", " + formatNumber(v.y) + ", " + formatNumber(v.z) + "]";
}

bool hasVdbExtension(const fs::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".vdb";
}

/// A shallow copy (grids shared) carrying the editor as creator.
MaterialSet forWriting(const MaterialSet& set) {
  MaterialSet out = set;
  out.creator = kCreator;
  return out;
}

/// A draft frame's settings: the same view on the draft grid.
LpvSettings draftSettings(LpvSettings s) {
  // A fixed step count is a reach in cells: the coarser grid needs proportionally fewer
  // steps to carry light as far.
  if (!s.autoSteps)
    s.steps = std::max(1, int(std::lround(double(s.steps) * kDraftPreviewResolution / double(s.resolution))));
  s.resolution = kDraftPreviewResolution;
  return s;
}

/// Of two finished frames, the one showing the newer request.
void keepNewer(std::optional<PreviewFrame>& best, std::optional<PreviewFrame> candidate) {
  if (candidate && (!best || candidate->serial > best->serial)) best = std::move(candidate);
}

void unite(std::optional<Bounds>& into, const Bounds& b) {
  if (b.empty()) return;
  if (!into) {
    into = b;
  } else {
    into->extend(b.min);
    into->extend(b.max);
  }
}

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// The checks the scene loader applies to a camera, for cameras coming from the window.
void checkCamera(const Camera& c) {
  const std::string what = "preview camera: ";
  if (!finite(c.position) || !finite(c.target) || !finite(c.up))
    throw InputError(what + "position, target and up must be finite");
  if (!(c.fovYDeg > 0.0 && c.fovYDeg < 180.0)) throw InputError(what + "fov_y_deg must be in (0, 180)");
  const glm::dvec3 view = c.target - c.position;
  const double length = glm::length(view);
  if (!(length > 0.0)) throw InputError(what + "target equals position: the view direction is undefined");
  const double up = glm::length(c.up);
  if (!(up > 0.0) || glm::length(glm::cross(view / length, c.up / up)) < 1e-6)
    throw InputError(what + "up is parallel to the view direction");
}

void checkSettings(const LpvSettings& s) {
  if (s.resolution < 2 || s.resolution > kMaxLpvResolution)
    throw InputError("preview lpv.resolution: expected an integer in [2, " + std::to_string(kMaxLpvResolution) +
                     "], got " + std::to_string(s.resolution));
  if (!s.autoSteps && (s.steps < 1 || s.steps > kMaxSteps))
    throw InputError("preview lpv.steps: expected an integer in [1, " + std::to_string(kMaxSteps) + "], got " +
                     std::to_string(s.steps));
  if (s.shadowMap < 1 || s.shadowMap > kMaxShadowMap)
    throw InputError("preview lpv.shadow_map: expected an integer in [1, " + std::to_string(kMaxShadowMap) +
                     "], got " + std::to_string(s.shadowMap));
}

}  // namespace

std::optional<fs::path> findRecoveryFile(const fs::path& sceneFile) {
  const fs::path file = recoveryPathFor(sceneFile);
  std::error_code ec;
  if (fs::is_regular_file(file, ec)) return file;
  return std::nullopt;
}

struct EditSession::Impl {
  Scene scene;
  SessionPaths paths;
  /// makePaintTarget(scene) without its set: what recover() puts the recovered set into.
  PaintTarget targetTemplate;
  std::unique_ptr<BrushEngine> engine;

  // Saved state. Every history entry carries a revision id; undoIds/redoIds mirror the
  // engine's undo and redo stacks, baseId is the state below the whole history. A stroke
  // that changed no voxel shares the id of the state it started from (nothing differs).
  std::uint64_t baseId = 0;
  std::uint64_t nextId = 1;
  std::uint64_t savedId = 0;
  std::vector<std::uint64_t> undoIds, redoIds;
  bool strokeWrote = false;  ///< the stroke in progress has written voxels
  std::uint64_t changes = 0;
  std::uint64_t autosavedChanges = 0;

  // Preview: one worker per quality; `draft` has none when drafts are full frames.
  struct PreviewChannel {
    std::unique_ptr<PreviewWorker> worker;
    LpvSettings settings;
    std::optional<Bounds> touched;  ///< world region changed since this channel's last request
    bool wholeSet = true;           ///< the whole set changed (start, recover, a region lost)
    bool cameraChanged = false;
    std::uint64_t requestedVersion = 0;
  };
  PreviewChannel full, draft;
  std::string backendName;
  int previewWidth = 0, previewHeight = 0;
  int previewLongestSide = 256;
  Camera camera;
  std::uint64_t version = 1;          ///< bumps with every change a preview shows
  std::uint64_t materialVersion = 1;  ///< bumps with every change of the voxels
  /// The set as of materialVersion snapshotVersion, shared by the jobs that carry it.
  std::shared_ptr<const MaterialSet> snapshot;
  std::uint64_t snapshotVersion = 0;
  std::uint64_t nextSerial = 1;
  std::uint64_t shownSerial = 0;  ///< the newest frame takePreview() returned

  std::uint64_t topId() const { return undoIds.empty() ? baseId : undoIds.back(); }

  PreviewChannel& channel(PreviewQuality quality) {
    return quality == PreviewQuality::Draft && draft.worker ? draft : full;
  }
  const PreviewChannel& channel(PreviewQuality quality) const {
    return quality == PreviewQuality::Draft && draft.worker ? draft : full;
  }

  void materialChanged(const Bounds& region) {
    for (PreviewChannel* c : {&full, &draft}) unite(c->touched, region);
    ++version;
    ++materialVersion;
  }

  void wholeSetChanged() {
    for (PreviewChannel* c : {&full, &draft}) {
      c->wholeSet = true;
      c->touched.reset();
    }
    ++version;
    ++materialVersion;
  }

  /// Deep: the engine paints its set in place while the workers read their copy.
  std::shared_ptr<const MaterialSet> snapshotSet() {
    if (!snapshot || snapshotVersion != materialVersion) {
      snapshot = deepCopy(*engine->materialSet());
      snapshotVersion = materialVersion;
    }
    return snapshot;
  }

  StrokeResult recordStroke(const StrokeResult& result) {
    undoIds.push_back(result.voxelsChanged > 0 ? nextId++ : topId());
    redoIds.clear();  // the engine drops its redo records too
    strokeWrote = false;
    ++changes;
    materialChanged(result.worldBounds);
    return result;
  }

  template <class Call>
  DabResult dabs(Call&& call) {
    try {
      const DabResult result = call();
      if (result.voxelsWritten > 0) {
        strokeWrote = true;
        materialChanged(result.worldBounds);
      }
      return result;
    } catch (...) {
      // Dabs before the failing one may have written voxels whose region was not returned.
      if (engine->strokeInProgress()) wholeSetChanged();
      throw;
    }
  }

  void requireNoStroke(const char* action) const {
    if (engine->strokeInProgress())
      throw InputError(std::string(action) + ": a stroke is in progress; end it first");
  }
};

EditSession::EditSession(const fs::path& sceneFile, const PreviewOptions& preview)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.scene = loadScene(sceneFile);
  m.paths.scene = sceneFile;
  m.paths.recovery = recoveryPathFor(sceneFile);
  if (m.scene.material.vdb) {
    m.paths.saveTarget = *m.scene.material.vdb;
  } else {
    // Normalized as the scene loader resolves material.vdb, so scene().material.vdb
    // compares equal after the save.
    m.paths.saveTarget = (sceneFile.parent_path() / (sceneFile.stem().string() + "_material.vdb")).lexically_normal();
    m.paths.saveUpdatesScene = true;
  }

  // Temporaries of a session that was killed mid-save: nothing reads them, and the next
  // save of each file might be long in coming.
  for (const fs::path& file : {m.paths.saveTarget, m.paths.recovery, m.paths.scene}) removeStaleTemporaries(file);

  PaintTarget target = makePaintTarget(m.scene);
  // A set some other tool wrote (an example's hand-made set) is not replaced without the
  // user's word, nor is an existing file the scene does not name.
  std::error_code ignored;
  if (m.scene.material.vdb) {
    const std::string& creator = target.set->creator;
    m.paths.saveNeedsConfirmation =
        std::none_of(std::begin(kPaintedCreators), std::end(kPaintedCreators),
                     [&](const char* painted) { return creator == painted; });
  } else {
    m.paths.saveNeedsConfirmation = fs::exists(m.paths.saveTarget, ignored);
  }
  m.targetTemplate = target;
  m.targetTemplate.set.reset();
  m.engine = std::make_unique<BrushEngine>(std::move(target));

  const LpvSettings settings = preview.lpv.value_or(m.scene.lpv);
  checkSettings(settings);
  if (preview.longestSide < kMinPreviewSide || preview.longestSide > kMaxImageSide)
    throw InputError("preview size: the longest side must be in [" + std::to_string(kMinPreviewSide) + ", " +
                     std::to_string(kMaxImageSide) + "] pixels, got " + std::to_string(preview.longestSide));
  const Camera& sceneCamera = m.scene.camera;
  const double scale = double(preview.longestSide) / double(std::max(sceneCamera.width, sceneCamera.height));
  m.previewWidth = std::max(kMinPreviewSide, int(std::lround(sceneCamera.width * scale)));
  m.previewHeight = std::max(kMinPreviewSide, int(std::lround(sceneCamera.height * scale)));
  m.previewLongestSide = preview.longestSide;
  m.camera = sceneCamera;
  m.camera.width = m.previewWidth;
  m.camera.height = m.previewHeight;

  // The renderer gets a snapshot of the engine's set with its first job, so it need not
  // load the file again.
  Scene previewScene = m.scene;
  previewScene.camera = m.camera;
  previewScene.material.vdb.reset();
  const PreviewRendererFactory make =
      preview.makeRenderer ? preview.makeRenderer : PreviewRendererFactory(makeRenderer);
  std::unique_ptr<Renderer> renderer = make(previewScene, preview.backend);
  m.backendName = renderer->name();
  // Drafts render on the CPU whatever the backend: a 16³ frame takes milliseconds there,
  // less than creating a second Vulkan device would. Both renderers exist before either
  // worker thread starts (the mesh reader forks).
  std::unique_ptr<Renderer> draftRenderer;
  if (settings.resolution > kDraftPreviewResolution) draftRenderer = make(previewScene, BackendKind::Cpu);
  m.full.settings = settings;
  m.full.worker = std::make_unique<PreviewWorker>(std::move(renderer));
  if (draftRenderer) {
    m.draft.settings = draftSettings(settings);
    m.draft.worker = std::make_unique<PreviewWorker>(std::move(draftRenderer));
    m.draft.cameraChanged = true;  // its first job gives it the draft's image size
  }
}

EditSession::~EditSession() = default;

const Scene& EditSession::scene() const { return impl_->scene; }
const SessionPaths& EditSession::paths() const { return impl_->paths; }
const BrushEngine& EditSession::engine() const { return *impl_->engine; }
const TriangleMesh& EditSession::worldMesh() const { return *impl_->targetTemplate.worldMesh; }

void EditSession::beginStroke(const Brush& brush) {
  Impl& m = *impl_;
  // The engine would end the running stroke itself; ending it here records it.
  if (m.engine->strokeInProgress()) endStroke();
  m.engine->beginStroke(brush);
  m.strokeWrote = false;
}

DabResult EditSession::addPoints(const std::vector<glm::dvec3>& worldPoints) {
  Impl& m = *impl_;
  return m.dabs([&] { return m.engine->addPoints(worldPoints); });
}

DabResult EditSession::addRays(const std::vector<SurfaceRay>& worldRays) {
  Impl& m = *impl_;
  return m.dabs([&] { return m.engine->addRays(worldRays); });
}

StrokeResult EditSession::endStroke() {
  Impl& m = *impl_;
  return m.recordStroke(m.engine->endStroke());
}

StrokeResult EditSession::applyStroke(const Stroke& stroke) {
  // The engine's applyStroke, step by step, so every history entry gets its id.
  beginStroke(stroke.brush);
  try {
    if (!stroke.points.empty()) addPoints(stroke.points);
    if (!stroke.rays.empty()) addRays(stroke.rays);
  } catch (...) {
    endStroke();
    throw;
  }
  return endStroke();
}

std::optional<StrokeResult> EditSession::undo() {
  Impl& m = *impl_;
  std::optional<StrokeResult> result = m.engine->undo();
  if (!result) return result;
  m.redoIds.push_back(m.undoIds.back());
  m.undoIds.pop_back();
  ++m.changes;
  m.materialChanged(result->worldBounds);
  return result;
}

std::optional<StrokeResult> EditSession::redo() {
  Impl& m = *impl_;
  std::optional<StrokeResult> result = m.engine->redo();
  if (!result) return result;
  m.undoIds.push_back(m.redoIds.back());
  m.redoIds.pop_back();
  ++m.changes;
  m.materialChanged(result->worldBounds);
  return result;
}

bool EditSession::canUndo() const { return impl_->engine->canUndo(); }
bool EditSession::canRedo() const { return impl_->engine->canRedo(); }

bool EditSession::unsaved() const { return impl_->strokeWrote || impl_->topId() != impl_->savedId; }
std::uint64_t EditSession::changeCount() const { return impl_->changes; }

void EditSession::setPreviewCamera(const Camera& camera) {
  Impl& m = *impl_;
  checkCamera(camera);
  m.camera = camera;
  m.camera.width = m.previewWidth;
  m.camera.height = m.previewHeight;
  m.full.cameraChanged = m.draft.cameraChanged = true;
  ++m.version;
}

void EditSession::setPreviewAspect(double widthOverHeight) {
  Impl& m = *impl_;
  if (!(widthOverHeight > 0.0) || !std::isfinite(widthOverHeight)) return;
  // Within 1:16 either way: a sliver of a window still gets a usable frame.
  const double aspect = std::clamp(widthOverHeight, 1.0 / 16.0, 16.0);
  const int side = m.previewLongestSide;
  const int width = std::max(kMinPreviewSide, int(std::lround(aspect >= 1.0 ? side : side * aspect)));
  const int height = std::max(kMinPreviewSide, int(std::lround(aspect >= 1.0 ? side / aspect : side)));
  if (width == m.previewWidth && height == m.previewHeight) return;
  m.previewWidth = m.camera.width = width;
  m.previewHeight = m.camera.height = height;
  m.full.cameraChanged = m.draft.cameraChanged = true;
  ++m.version;
}

const Camera& EditSession::previewCamera() const { return impl_->camera; }
bool EditSession::previewStale(PreviewQuality quality) const {
  return impl_->channel(quality).requestedVersion != impl_->version;
}

std::uint64_t EditSession::requestPreview(PreviewQuality quality) {
  Impl& m = *impl_;
  Impl::PreviewChannel& c = m.channel(quality);
  PreviewJob job;
  job.serial = m.nextSerial++;
  job.draft = &c == &m.draft;
  job.settings = c.settings;
  if (c.wholeSet || c.touched) {
    job.set = m.snapshotSet();
    job.wholeSet = c.wholeSet;
    job.touched = c.touched;
    c.wholeSet = false;
    c.touched.reset();
  }
  if (c.cameraChanged) {
    job.camera = m.camera;
    // Half the pixels each way: shading is most of a 16³ frame's time, and the window
    // scales the image to the same size on screen.
    if (job.draft) {
      job.camera->width = std::max(kMinPreviewSide, (m.previewWidth + 1) / 2);
      job.camera->height = std::max(kMinPreviewSide, (m.previewHeight + 1) / 2);
    }
  }
  c.cameraChanged = false;
  c.requestedVersion = m.version;
  // A full frame of this state makes a draft of it pointless.
  if (&c == &m.full) m.draft.requestedVersion = m.version;
  const std::uint64_t serial = job.serial;
  c.worker->submit(std::move(job));
  return serial;
}

std::optional<PreviewFrame> EditSession::takePreview() {
  Impl& m = *impl_;
  std::optional<PreviewFrame> newest;
  for (Impl::PreviewChannel* c : {&m.full, &m.draft})
    if (c->worker) keepNewer(newest, c->worker->take());
  if (!newest || newest->serial <= m.shownSerial) return std::nullopt;
  m.shownSerial = newest->serial;
  return newest;
}

bool EditSession::previewBusy(PreviewQuality quality) const { return impl_->channel(quality).worker->busy(); }

std::optional<PreviewFrame> EditSession::waitForPreview() {
  Impl& m = *impl_;
  std::optional<PreviewFrame> newest;
  for (Impl::PreviewChannel* c : {&m.full, &m.draft})
    if (c->worker) keepNewer(newest, c->worker->wait());
  if (!newest || newest->serial <= m.shownSerial) return std::nullopt;
  m.shownSerial = newest->serial;
  return newest;
}

Image EditSession::renderPreview(RenderReport* report) {
  const std::uint64_t serial = requestPreview(PreviewQuality::Full);
  // The newest request, so the frame waitForPreview() returns is this one.
  std::optional<PreviewFrame> frame = waitForPreview();
  if (!frame || frame->serial != serial) throw std::logic_error("renderPreview: the requested frame went missing");
  if (frame->failure) std::rethrow_exception(frame->failure);
  if (report) *report = frame->report;
  return std::move(frame->image);
}

std::string EditSession::previewBackendName() const { return impl_->backendName; }
const LpvSettings& EditSession::previewSettings() const { return impl_->full.settings; }
int EditSession::draftResolution() const { return impl_->channel(PreviewQuality::Draft).settings.resolution; }

void EditSession::save(bool replaceConfirmed) {
  Impl& m = *impl_;
  if (m.paths.saveNeedsConfirmation && !replaceConfirmed)
    throw SaveNeedsConfirmation(m.paths.saveTarget.string() +
                                ": not written by sslpv's painting tools (it may be a hand-made material set): "
                                "confirm to replace it, or save as another file");
  writeSaved(m.paths.saveTarget, m.paths.saveUpdatesScene);
}

void EditSession::saveAs(const fs::path& vdbFile, bool replaceConfirmed) {
  if (!hasVdbExtension(vdbFile)) throw InputError(vdbFile.string() + ": the material set must be a .vdb file");
  const fs::path target = vdbFile.lexically_normal();
  std::error_code ignored;
  const bool same = impl_->scene.material.vdb && fs::equivalent(target, *impl_->scene.material.vdb, ignored);
  if (same) return save(replaceConfirmed);
  if (fs::exists(target, ignored) && !replaceConfirmed)
    throw SaveNeedsConfirmation(target.string() + ": the file exists: confirm to replace it");
  writeSaved(target, /*nameInScene=*/true);
}

bool EditSession::cameraUnsaved() const { return !sameView(impl_->camera, impl_->scene.camera); }

void EditSession::writeSaved(const fs::path& target, bool nameInScene) {
  Impl& m = *impl_;
  // Mid-stroke the voxels match no history position, so "saved" could not be recorded.
  m.requireNoStroke("save");
  const MaterialSet out = forWriting(*m.engine->materialSet());
  const bool camera = cameraUnsaved();
  if (!nameInScene && !camera) {
    saveMaterialSet(out, target);
  } else {
    const fs::path& sceneFile = m.paths.scene;
    requireWritableOutput(target);
    requireWritableOutput(sceneFile);
    const std::string original = readFile(sceneFile);
    // Only the values that change are replaced in the text: the author's layout, number
    // spelling and key order stay (a generic JSON writer turned 15 lines into 90).
    std::string text = nameInScene ? sceneTextNamingVdb(sceneFile, original, target) : original;
    if (camera) {
      const Camera& c = m.camera;
      text = spliceJsonValue(text, {"camera", "position"}, jsonVec3(c.position), sceneFile);
      text = spliceJsonValue(text, {"camera", "target"}, jsonVec3(c.target), sceneFile);
      Camera upOnly = m.scene.camera;
      upOnly.up = c.up;
      if (!sameView(upOnly, m.scene.camera))
        text = spliceJsonValue(text, {"camera", "up"}, jsonVec3(glm::normalize(c.up)), sceneFile);
      text = spliceJsonValue(text, {"camera", "fov_y_deg"}, formatNumber(c.fovYDeg), sceneFile);
    }
    // Refuse to write a scene the loader would reject (the file may have changed on disk).
    const Scene written = parseScene(text, sceneFile);
    // Both files go to temporaries first, then the material is renamed into place before
    // the scene that names it: killed between the two renames, the previous scene (which
    // does not name the new file) stays, never a scene naming a file that is not there
    // yet. A failure before the renames leaves both previous files.
    writeAtomicallyTogether({{target, [&](const fs::path& temp) { saveMaterialSet(out, temp); }},
                             sceneTextOutput(sceneFile, text)});
    m.scene.material.vdb = written.material.vdb;
    m.scene.camera = written.camera;
    m.paths.saveUpdatesScene = false;
  }
  m.paths.saveTarget = target;
  m.paths.saveNeedsConfirmation = false;  // from now on the file holds this session's work
  m.savedId = m.topId();
  // The saved file now holds everything the recovery file did.
  std::error_code ignored;
  fs::remove(m.paths.recovery, ignored);
}

void EditSession::exportMaterialSet(const fs::path& vdbFile) const {
  if (!hasVdbExtension(vdbFile)) throw InputError(vdbFile.string() + ": the export must be a .vdb file");
  requireWritableOutput(vdbFile);
  saveMaterialSet(forWriting(*impl_->engine->materialSet()), vdbFile);
}

void EditSession::autosave() {
  Impl& m = *impl_;
  saveMaterialSet(forWriting(*m.engine->materialSet()), m.paths.recovery);
  m.autosavedChanges = m.changes;
}

bool EditSession::autosaveStale() const { return unsaved() && impl_->changes != impl_->autosavedChanges; }

void EditSession::recover() {
  Impl& m = *impl_;
  // The window's drag would continue on an engine that no longer has its stroke.
  m.requireNoStroke("recover");
  const fs::path& file = m.paths.recovery;
  std::shared_ptr<const MaterialSet> loaded;
  try {
    loaded = loadMaterialSet(file);
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (message.find(file.string()) != std::string::npos) throw;
    throw InputError(file.string() + ": " + message);
  }
  // Painting needs its own grids: the loaded ones are const and may be shared.
  PaintTarget target = m.targetTemplate;
  target.set = deepCopy(*loaded);
  std::unique_ptr<BrushEngine> engine;
  try {
    engine = std::make_unique<BrushEngine>(std::move(target));
  } catch (const InputError& e) {
    throw InputError(file.string() + ": does not fit the scene: " + e.what());
  }

  // Nothing below throws: the session changes only once the recovered set is usable.
  m.engine = std::move(engine);
  m.undoIds.clear();
  m.redoIds.clear();
  m.baseId = m.nextId++;  // never the saved id: a recovered state is unsaved
  m.strokeWrote = false;
  ++m.changes;
  m.autosavedChanges = m.changes;  // the recovery file holds exactly this state
  m.wholeSetChanged();
}

void EditSession::discardRecovery() {
  const fs::path& file = impl_->paths.recovery;
  std::error_code ec;
  fs::remove(file, ec);
  if (ec) throw InputError(file.string() + ": cannot delete the recovery file: " + ec.message());
}

}  // namespace sslpv
