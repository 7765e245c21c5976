#pragma once
// The editor's document: one scene, its material set being painted (BrushEngine), the
// live SSLPV preview, and the file side (save, export, autosave, crash recovery). No VTK:
// the window (editor/ui/) drives it, tests and benchmarks drive it headless.
//
// Files. Save writes the painted set to the scene's material.vdb. A scene without one
// gets <scene dir>/<scene stem>_material.vdb, and Save then also updates the scene JSON
// so that material.vdb names it. Save As writes to a file the user names and points
// material.vdb there. A save also records the view when the camera moved (camera.position,
// target, up, fov_y_deg). Scene updates replace those values in the text and leave every
// other byte as it was. Save does not replace, without confirmation, a set that sslpv's
// painting tools did not write (an example's hand-made set) or an existing file the scene
// does not name. Every write is atomic (temporary file + rename): a failed save leaves
// the previous files and the in-memory state (painted voxels, history, unsaved flag)
// exactly as they were. A session killed mid-write (SIGKILL) leaves at most a temporary
// beside the file, which the next session removes when it opens the scene.
//
// Recovery. While there are unsaved changes the window calls autosave() a few seconds
// after the last change; it writes the current set to <scene file>.recovery.vdb (same
// directory as the scene). A normal save or a clean exit deletes that file, so finding it
// at start means the previous session ended without saving (crash, kill): the window
// offers recover() or discardRecovery(). The undo history is not part of the recovery
// file; a recovered state counts as unsaved.
#include <chrono>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backend/backends.h"
#include "editor/brush_engine.h"
#include "volume/lpv/frame_report.h"
#include "volume/core/error.h"
#include "volume/core/image_io.h"
#include "volume/scene/scene.h"

namespace sslpv {

/// Builds a preview renderer. Tests put a deliberately slow or counting renderer here.
using PreviewRendererFactory = std::function<std::unique_ptr<Renderer>(const Scene&, BackendKind)>;

/// The grid of the draft frames shown during a stroke (PreviewQuality::Draft).
constexpr int kDraftPreviewResolution = 16;

struct PreviewOptions {
  BackendKind backend = BackendKind::Cpu;
  /// Longest side of the preview image in pixels; the scene camera's aspect is kept.
  int longestSide = 256;
  /// LPV settings of the preview; absent: the scene's lpv settings.
  std::optional<LpvSettings> lpv;
  /// Absent: makeRenderer (backend/backends.h), a Vulkan preview on a device of its own.
  PreviewRendererFactory makeRenderer;
};

/// Full: the preview's own settings. Draft: the same view on a kDraftPreviewResolution³
/// grid at half the image size each way, for the frames during a stroke; where the
/// preview's grid is not finer than that, a draft is a full frame.
enum class PreviewQuality { Draft, Full };

/// One finished preview frame, rendered off the UI thread.
struct PreviewFrame {
  Image image;  ///< empty when `error` is set
  RenderReport report;
  std::uint64_t serial = 0;  ///< the requestPreview() whose state it shows
  bool draft = false;
  int resolution = 0;    ///< LPV grid side
  double renderMs = 0;   ///< the worker's wall time for the frame
  std::chrono::steady_clock::time_point finished;
  std::string error;     ///< the render failed: the one-line reason
  std::exception_ptr failure;  ///< and what the renderer threw
};

struct SessionPaths {
  std::filesystem::path scene;       ///< the scene JSON
  std::filesystem::path saveTarget;  ///< where save() writes the material set
  bool saveUpdatesScene = false;     ///< the scene had no material.vdb: save() also rewrites the scene JSON
  /// save() needs the user's confirmation: saveTarget holds work not from this session or
  /// sslpv's painting tools (creator other than "sslpv edit"/"sslpv paint"), or exists
  /// while the scene does not name it.
  bool saveNeedsConfirmation = false;
  std::filesystem::path recovery;    ///< <scene file>.recovery.vdb
};

/// save()/saveAs() would replace a file the user has not agreed to replace; nothing was
/// written. The window asks and calls again with the confirmation.
class SaveNeedsConfirmation : public InputError {
 public:
  using InputError::InputError;
};

/// The recovery file <scene file>.recovery.vdb when it exists.
std::optional<std::filesystem::path> findRecoveryFile(const std::filesystem::path& sceneFile);

class EditSession {
 public:
  /// Loads the scene, its mesh and material set (InputError naming the file on bad input)
  /// and creates the preview renderer (GpuError when Vulkan was asked for and is missing).
  EditSession(const std::filesystem::path& sceneFile, const PreviewOptions& preview);
  ~EditSession();
  EditSession(const EditSession&) = delete;
  EditSession& operator=(const EditSession&) = delete;

  const Scene& scene() const;
  const SessionPaths& paths() const;
  const BrushEngine& engine() const;
  /// The object's world mesh (for the window's 3D view and picking).
  const TriangleMesh& worldMesh() const;

  // Painting: the engine's calls; each records the touched region for the next preview
  // and the unsaved state. Exceptions as in BrushEngine.
  void beginStroke(const Brush& brush);
  DabResult addPoints(const std::vector<glm::dvec3>& worldPoints);
  DabResult addRays(const std::vector<SurfaceRay>& worldRays);
  StrokeResult endStroke();
  StrokeResult applyStroke(const Stroke& stroke);
  std::optional<StrokeResult> undo();
  std::optional<StrokeResult> redo();
  bool canUndo() const;
  bool canRedo() const;

  /// True when the material differs from the last saved (or loaded, or recovered-from)
  /// state by history position: paint + undo back to the saved stroke is saved again.
  bool unsaved() const;
  /// Number of changes (strokes, undos, redos) since the session started; the window
  /// compares it to decide when the preview and the autosave are stale.
  std::uint64_t changeCount() const;

  // Preview. Frames are rendered on worker threads (editor/preview_worker.h): the calls
  // below never wait for a render, except renderPreview() and waitForPreview().
  void setPreviewCamera(const Camera& camera);  ///< width/height are replaced by the preview size
  const Camera& previewCamera() const;
  /// The preview image's width / height (the 3D view's, when the preview is the main view),
  /// its longest side still the PreviewOptions one; junk (0, NaN) is ignored.
  void setPreviewAspect(double widthOverHeight);
  /// True when a stroke, dab, undo, redo or camera change happened since the last request
  /// of `quality` (a Full request or renderPreview() also satisfies Draft).
  bool previewStale(PreviewQuality quality = PreviewQuality::Full) const;
  /// Hands the current state to the preview's worker and returns at once with the
  /// request's serial. What the worker reads is copied here (the set only where it
  /// changed since the last request): painting on goes on while it renders. A request not
  /// yet started is replaced by this one; a frame in progress finishes first.
  std::uint64_t requestPreview(PreviewQuality quality);
  /// The newest finished frame not returned before, if it shows a newer request than
  /// every frame returned so far (an older state finishing late is dropped).
  std::optional<PreviewFrame> takePreview();
  /// A requested frame of `quality` is pending or rendering.
  bool previewBusy(PreviewQuality quality) const;
  /// Waits until every requested frame is finished, then takePreview().
  std::optional<PreviewFrame> waitForPreview();
  /// requestPreview(Full) and its frame: re-renders what changed since the last full
  /// frame (only the touched region is resampled). Throws what the renderer threw.
  Image renderPreview(RenderReport* report = nullptr);
  std::string previewBackendName() const;
  const LpvSettings& previewSettings() const;
  /// The LPV grid side of a draft frame (the preview's when drafts are full frames).
  int draftResolution() const;

  // Files. Throw InputError/ResourceError with a one-line reason; on failure nothing in
  // memory changes and the previous files stay intact.
  /// Throws SaveNeedsConfirmation when paths().saveNeedsConfirmation and not `replaceConfirmed`.
  void save(bool replaceConfirmed = false);
  /// Writes the set to `vdbFile` (.vdb) and makes it the scene's material.vdb (the scene
  /// file changes in that value only) and the target of later saves. An existing file
  /// needs `replaceConfirmed` (SaveNeedsConfirmation otherwise).
  void saveAs(const std::filesystem::path& vdbFile, bool replaceConfirmed = false);
  /// The preview camera differs from the scene file's: the next save records it.
  bool cameraUnsaved() const;
  /// Writes the current set to `vdbFile` (must end in .vdb); the saved state is unchanged.
  void exportMaterialSet(const std::filesystem::path& vdbFile) const;
  /// Writes the recovery file (atomically). Records changeCount() as autosaved.
  void autosave();
  /// Unsaved changes that autosave() has not written yet.
  bool autosaveStale() const;
  /// Replaces the material with the recovery file's (InputError when it is unreadable or
  /// does not fit the scene); clears the history; the state counts as unsaved.
  void recover();
  /// Deletes the recovery file (after the user declined it, or at a clean exit).
  void discardRecovery();

 private:
  void writeSaved(const std::filesystem::path& target, bool nameInScene);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sslpv
