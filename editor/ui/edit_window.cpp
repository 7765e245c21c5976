#include "editor/ui/edit_window.h"

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellPicker.h>
#include <vtkCellArray.h>
#include <vtkImageActor.h>
#include <vtkImageData.h>
#include <vtkImageMapper3D.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <glm/gtc/matrix_inverse.hpp>

#include "editor/ui/slice_views.h"
#include "volume/core/error.h"
#include "volume/material/material_field.h"

namespace sslpv {
namespace {

// Window layout (normalized viewports): 3D view and preview on top, three slices below
// (the status line is the Qt window's status bar).
constexpr double kSliceRowTop = 0.34;
constexpr int kSliceSamples = 128;

const char* kHelpText =
    "sslpv edit - keys\n"
    "  Space        paint / camera mode (left drag paints in paint mode)\n"
    "  left drag    3D view: paint on the surface along the view ray\n"
    "               slice views: paint on the slice plane\n"
    "  right/middle drag, wheel   camera (3D view); wheel over a slice moves it\n"
    "  Up / Down    move the slice under the mouse\n"
    "  c / C        channel: colour, sigma_t, sigma_s, g, albedo+mfp, preset, all\n"
    "  m / M        mode: set, add, multiply, smooth, erase\n"
    "  , / .        value down / up (sigma x1.25, g 0.05, mfp and scatter distance x1.25, preset)\n"
    "  ; / '        albedo (albedo+mfp) or surface colour (colour) down / up\n"
    "  g / G        colour: phase g up / down        p / P   next / previous swatch\n"
    "  Enter        colour: type surface colour, scatter distance, g (Enter keeps a field)\n"
    "  click        a swatch under the 3D view: paint that material's colour\n"
    "  v            edit all / red / green / blue component of the value\n"
    "  n            negate the add amount\n"
    "  [ / ]        radius smaller / larger\n"
    "  - / =        strength down / up\n"
    "  o            falloff: constant, linear, smooth, gaussian\n"
    "  x            mirror: off, x, y, z\n"
    "  i / I        surface depth deeper / shallower\n"
    "  Ctrl+Z       undo        Ctrl+Y, Ctrl+Shift+Z   redo\n"
    "  Ctrl+S       save        Ctrl+Shift+S  save as (type a path)\n"
    "  Ctrl+E       export a copy of the material set (type a path)\n"
    "  b            the live SSLPV preview as the 3D view (mesh hidden) / back\n"
    "  l            lock the slices' colour range where it is / unlock\n"
    "  R / D        recover / discard unsaved work from a previous session\n"
    "  h, ?, F1     this help   q, e   quit (asks when there are unsaved changes)\n"
    "  VTK camera keys: r reset, f fly to, w wireframe, s surface, 3 stereo";

vtkSmartPointer<vtkTextActor> makeText(vtkRenderer* renderer, int fontSize, double x, double y) {
  auto text = vtkSmartPointer<vtkTextActor>::New();
  text->GetTextProperty()->SetFontSize(fontSize);
  text->GetTextProperty()->SetFontFamilyToCourier();
  text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  text->SetPosition(x, y);
  renderer->AddViewProp(text);
  return text;
}

vtkSmartPointer<vtkPolyData> toPolyData(const TriangleMesh& mesh) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetNumberOfPoints(vtkIdType(mesh.positions.size()));
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    points->SetPoint(vtkIdType(i), mesh.positions[i].x, mesh.positions[i].y, mesh.positions[i].z);
  auto triangles = vtkSmartPointer<vtkCellArray>::New();
  for (const glm::uvec3& t : mesh.triangles) {
    const vtkIdType ids[3] = {vtkIdType(t.x), vtkIdType(t.y), vtkIdType(t.z)};
    triangles->InsertNextCell(3, ids);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(triangles);
  return poly;
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

EditWindow::EditWindow(EditSession& session, const EditWindowOptions& options)
    : session_(session),
      options_(options),
      controls_(session.scene().material.base, glm::length(session.worldMesh().bounds().extent()) / std::sqrt(3.0),
                session.scene().units, session.scene().material.ior) {
  recoveryPending_ = options.offerRecovery && findRecoveryFile(session.scene().file).has_value();
  buildScene();
  updateSlices();
  // The first frame renders everything and can take seconds: the window opens at once and
  // shows the progress note until it arrives.
  requestPreview(PreviewQuality::Full);
  updatePreviewLabel();
  updateStatus();
  if (recoveryPending_) {
    const std::filesystem::path file = *findRecoveryFile(session.scene().file);
    showMessage("Unsaved work from an earlier session is in " + file.filename().string() +
                    ": press R to recover it or D to discard it (painting waits for the answer)",
                false);
  }
}

EditWindow::~EditWindow() = default;

vtkRenderWindow* EditWindow::renderWindow() const { return window_; }
vtkRenderWindowInteractor* EditWindow::interactor() const { return interactor_; }

void EditWindow::buildScene() {
  if (!options_.host || !options_.host->GetInteractor())
    throw ResourceError("the editor's views need a render window with an interactor");
  window_ = options_.host;
  window_->SetNumberOfLayers(2);
  interactor_ = window_->GetInteractor();

  view3d_ = vtkSmartPointer<vtkRenderer>::New();
  view3d_->SetViewport(0.0, kSliceRowTop, 0.5, 1.0);
  view3d_->SetBackground(0.16, 0.17, 0.2);
  preview_ = vtkSmartPointer<vtkRenderer>::New();
  preview_->SetViewport(0.5, kSliceRowTop, 1.0, 1.0);
  preview_->SetBackground(0.0, 0.0, 0.0);
  preview_->InteractiveOff();
  window_->AddRenderer(view3d_);
  window_->AddRenderer(preview_);
  std::array<vtkRenderer*, 3> slices{};
  for (int a = 0; a < 3; ++a) {
    sliceViews_[a] = vtkSmartPointer<vtkRenderer>::New();
    sliceViews_[a]->SetViewport(a / 3.0, 0.0, (a + 1) / 3.0, kSliceRowTop);
    window_->AddRenderer(sliceViews_[a]);
    slices[a] = sliceViews_[a];
  }
  // Layer 1 (the overlay) does not clear: the layer-0 renderers above cover every pixel.
  overlay_ = vtkSmartPointer<vtkRenderer>::New();
  overlay_->SetLayer(1);
  overlay_->InteractiveOff();
  overlay_->SetViewport(0.0, 0.0, 1.0, 1.0);
  window_->AddRenderer(overlay_);

  vtkSmartPointer<vtkPolyData> mesh = toPolyData(session_.worldMesh());
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputData(mesh);
  meshActor_ = vtkSmartPointer<vtkActor>::New();
  meshActor_->SetMapper(mapper);
  // See-through, so the slices inside stay visible while the surface is still pickable.
  meshActor_->GetProperty()->SetOpacity(0.3);
  meshActor_->GetProperty()->SetColor(0.85, 0.85, 0.8);
  view3d_->AddActor(meshActor_);
  slices_ = std::make_unique<SliceViews>(session_.worldMesh().bounds(), mesh, view3d_, slices, kSliceSamples);

  // The brush cursor: a unit wire sphere scaled to the brush radius.
  auto sphere = vtkSmartPointer<vtkSphereSource>::New();
  sphere->SetThetaResolution(24);
  sphere->SetPhiResolution(12);
  auto sphereMapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  sphereMapper->SetInputConnection(sphere->GetOutputPort());
  auto makeCursor = [&](vtkRenderer* renderer) {
    auto actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(sphereMapper);
    actor->GetProperty()->SetRepresentationToWireframe();
    actor->GetProperty()->SetColor(1.0, 0.85, 0.2);
    actor->GetProperty()->SetOpacity(0.7);
    actor->PickableOff();
    actor->SetVisibility(false);
    renderer->AddActor(actor);
    return actor;
  };
  cursor3d_ = makeCursor(view3d_);
  for (int a = 0; a < 3; ++a) cursorSlice_[a] = makeCursor(sliceViews_[a]);
  picker_ = vtkSmartPointer<vtkCellPicker>::New();
  picker_->PickFromListOn();
  picker_->AddPickList(meshActor_);
  picker_->SetTolerance(1e-4);

  // The 3D view starts at the scene's camera, which is also the preview's.
  const Camera& c = session_.scene().camera;
  vtkCamera* camera = view3d_->GetActiveCamera();
  camera->SetPosition(c.position.x, c.position.y, c.position.z);
  camera->SetFocalPoint(c.target.x, c.target.y, c.target.z);
  camera->SetViewUp(c.up.x, c.up.y, c.up.z);
  camera->SetViewAngle(c.fovYDeg);
  view3d_->ResetCameraClippingRange();

  previewImage_ = vtkSmartPointer<vtkImageData>::New();
  previewActor_ = vtkSmartPointer<vtkImageActor>::New();
  previewActor_->GetMapper()->SetInputData(previewImage_);
  preview_->AddViewProp(previewActor_);

  previewLabel_ = makeText(overlay_, 12, 0.505, 0.965);
  previewLabel_->GetTextProperty()->SetColor(0.8, 0.8, 0.8);
  previewProgress_ = makeText(overlay_, 15, 0.75, 0.5 * (1.0 + kSliceRowTop));
  previewProgress_->GetTextProperty()->SetJustificationToCentered();
  previewProgress_->GetTextProperty()->SetVerticalJustificationToCentered();
  previewProgress_->GetTextProperty()->SetColor(1.0, 0.85, 0.2);
  previewProgress_->GetTextProperty()->SetBackgroundColor(0.0, 0.0, 0.0);
  previewProgress_->GetTextProperty()->SetBackgroundOpacity(0.7);
  previewProgress_->SetVisibility(false);
  help_ = makeText(overlay_, 14, 0.03, 0.12);
  help_->SetInput(kHelpText);
  help_->GetTextProperty()->SetBackgroundColor(0.0, 0.0, 0.0);
  help_->GetTextProperty()->SetBackgroundOpacity(0.85);
  help_->SetVisibility(false);
  buildSwatches();
}

void EditWindow::updateSlices() {
  const Scene& scene = session_.scene();
  const MaterialField field(scene.material.base, session_.engine().materialSet(),
                            glm::inverse(scene.transform.matrix()), 1.0 / session_.engine().sigmaToSetUnits());
  slices_->update(field, controls_.displayChannel(), scene.units);
}

void EditWindow::requestPreview(PreviewQuality quality) {
  try {
    session_.requestPreview(quality);
  } catch (const std::exception& e) {
    // Copying the set for the worker ran out of memory, say: painting goes on.
    showMessage(std::string("preview failed: ") + e.what(), true);
    return;
  }
  if (quality == PreviewQuality::Full || session_.draftResolution() == session_.previewSettings().resolution) {
    if (!fullPending_) fullRequestedAt_ = std::chrono::steady_clock::now();
    fullPending_ = true;
  }
}

bool EditWindow::pollPreview() {
  bool changed = false;
  if (std::optional<PreviewFrame> frame = session_.takePreview()) {
    showFrame(*frame);
    changed = true;
  }
  // Idle after the take: the full frame is on screen, or a newer draft replaced it.
  if (fullPending_ && !session_.previewBusy(PreviewQuality::Full)) fullPending_ = false;
  // The note appears once a full frame has kept the user waiting a second, and counts up.
  const bool waiting = fullPending_ && msSince(fullRequestedAt_) > 1000.0;
  std::string note;
  if (waiting) {
    char text[96];
    std::snprintf(text, sizeof text, "rendering the %d^3 preview... %.0f s", session_.previewSettings().resolution,
                  std::floor(msSince(fullRequestedAt_) / 1000.0));
    note = text;
  }
  const char* previous = previewProgress_->GetInput();
  if (waiting != (previewProgress_->GetVisibility() != 0) || (previous ? note != previous : !note.empty())) {
    previewProgress_->SetInput(note.c_str());
    previewProgress_->SetVisibility(waiting);
    changed = true;
  }
  return changed;
}

void EditWindow::settlePreview() {
  if (std::optional<PreviewFrame> frame = session_.waitForPreview()) showFrame(*frame);
  pollPreview();
}

void EditWindow::showFrame(const PreviewFrame& frame) {
  if (!frame.error.empty()) {
    showMessage("preview failed: " + frame.error, true);
    return;
  }
  const Image& image = frame.image;
  const std::vector<unsigned char> rgb = toDisplayRgb8(image);
  previewImage_->SetDimensions(image.width, image.height, 1);
  previewImage_->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* out = static_cast<unsigned char*>(previewImage_->GetScalarPointer());
  // The renderer's row 0 is the top; VTK's is the bottom.
  const std::size_t row = std::size_t(image.width) * 3;
  for (int y = 0; y < image.height; ++y)
    std::memcpy(out + std::size_t(image.height - 1 - y) * row, rgb.data() + std::size_t(y) * row, row);
  previewImage_->Modified();
  preview_->GetActiveCamera()->ParallelProjectionOn();
  preview_->ResetCamera();
  // Fill the view's height with the image (ResetCamera leaves a wide margin).
  preview_->GetActiveCamera()->SetParallelScale(0.5 * image.height);
  shown_ = frame;
  shown_->image = Image{};  // uploaded; the label needs the rest only
  updatePreviewLabel();
}

void EditWindow::updatePreviewLabel() {
  // "vulkan (llvmpipe (LLVM 15.0.6, 256 bits))" would run off the view: keep the device.
  std::string backend = session_.previewBackendName();
  if (const std::size_t inner = backend.find(" (", backend.find('(') + 1); inner != std::string::npos)
    backend = backend.substr(0, inner) + ")";
  char text[160];
  if (!shown_) {
    std::snprintf(text, sizeof text, "SSLPV preview (%s): rendering %d^3...", backend.c_str(),
                  session_.previewSettings().resolution);
  } else if (shown_->draft) {
    std::snprintf(text, sizeof text, "SSLPV preview (%s): draft %d^3, %.0f ms; %d^3 when the stroke ends",
                  backend.c_str(), shown_->resolution, shown_->renderMs, session_.previewSettings().resolution);
  } else {
    std::snprintf(text, sizeof text, "SSLPV preview (%s): %d^3, %.0f ms", backend.c_str(), shown_->resolution,
                  shown_->renderMs);
  }
  previewLabelText_ = text;
  previewLabel_->SetInput(previewLabelText_.c_str());
}

void EditWindow::updateStatus() {
  updateSwatches();
  if (stateListener_) stateListener_();
}

std::string EditWindow::statusText() const {
  std::string text = controls_.describe();
  if (previewMain_) text += " | 3D view: SSLPV preview";
  if (slices_ && slices_->range().locked()) text += " | range locked";
  return text + "   | h: help";
}

void EditWindow::setListeners(std::function<void()> state, std::function<void(const std::string&, bool)> message) {
  stateListener_ = std::move(state);
  messageListener_ = std::move(message);
  // A message from before the listeners existed (the recovery question at start-up).
  if (messageListener_ && !lastMessage_.empty()) messageListener_(lastMessage_, lastMessageError_);
  if (stateListener_) stateListener_();
}

void EditWindow::showMessage(const std::string& text, bool error) {
  if (error) {
    // Also on stderr: scripted runs and bug reports read it there.
    std::string line = text;
    std::replace(line.begin(), line.end(), '\n', ' ');
    std::fprintf(stderr, "sslpv edit: %s\n", line.c_str());
  }
  lastMessage_ = text;
  lastMessageError_ = error;
  if (messageListener_) messageListener_(text, error);
}

void EditWindow::refresh() {
  matchPreviewAspect();
  if (session_.previewStale()) requestPreview(PreviewQuality::Full);
  pollPreview();
  updateStatus();
  window_->Render();
}

vtkRenderer* EditWindow::rendererAt(int x, int y) const {
  return interactor_->FindPokedRenderer(x, y);
}

SurfaceRay EditWindow::rayAt(int x, int y) const {
  double nearPoint[4], farPoint[4];
  view3d_->SetDisplayPoint(x, y, 0.0);
  view3d_->DisplayToWorld();
  view3d_->GetWorldPoint(nearPoint);
  view3d_->SetDisplayPoint(x, y, 1.0);
  view3d_->DisplayToWorld();
  view3d_->GetWorldPoint(farPoint);
  glm::dvec3 a(nearPoint[0], nearPoint[1], nearPoint[2]), b(farPoint[0], farPoint[1], farPoint[2]);
  if (nearPoint[3] != 0.0) a /= nearPoint[3];
  if (farPoint[3] != 0.0) b /= farPoint[3];
  // The near plane can sit inside a large object; start at the camera instead.
  double eye[3];
  view3d_->GetActiveCamera()->GetPosition(eye);
  return SurfaceRay{glm::dvec3(eye[0], eye[1], eye[2]), b - a};
}

bool EditWindow::beginPaint(int x, int y) {
  if (!controls_.paintMode() || prompt_) return false;
  vtkRenderer* target = rendererAt(x, y);
  const std::optional<int> axis = slices_->axisOf(target);
  if (target != view3d_.Get() && !axis) return false;
  if (pickSwatchAt(x, y)) return true;
  if (recoveryPending_) {
    showMessage("Answer the recovery question first: R recovers the earlier session's work, D discards it", true);
    window_->Render();
    return true;
  }
  try {
    session_.beginStroke(controls_.brush());
    slices_->holdRange(true);
    paintView_ = axis ? PaintView::Slice : PaintView::Surface;
    paintAxis_ = axis.value_or(0);
    continuePaint(x, y);
  } catch (const std::exception& e) {
    showMessage(e.what(), true);
    paintView_ = PaintView::None;
  }
  return true;
}

void EditWindow::placeCursor(int x, int y) {
  const double radius = controls_.brush().radius;
  std::optional<glm::dvec3> at;
  std::optional<int> sliceAxis;
  if (controls_.paintMode() && !prompt_) {
    vtkRenderer* target = rendererAt(x, y);
    if (target == view3d_.Get()) {
      // The picker skips hidden actors; the mesh is hidden under the preview-as-view.
      meshActor_->SetVisibility(true);
      const bool hit = picker_->Pick(x, y, 0.0, view3d_) != 0;
      meshActor_->SetVisibility(!previewMain_);
      if (hit) {
        double p[3];
        picker_->GetPickPosition(p);
        at = glm::dvec3(p[0], p[1], p[2]);
      }
    } else if ((sliceAxis = slices_->axisOf(target))) {
      at = slices_->worldPointAt(*sliceAxis, x, y);
    }
  }
  std::array<vtkActor*, 4> cursors{cursor3d_, cursorSlice_[0], cursorSlice_[1], cursorSlice_[2]};
  for (vtkActor* cursor : cursors) {
    cursor->SetVisibility(at.has_value());
    if (!at) continue;
    cursor->SetPosition(at->x, at->y, at->z);
    cursor->SetScale(radius);
  }
  if (at) view3d_->ResetCameraClippingRange();
}

void EditWindow::hover(int x, int y) {
  const bool wasVisible = cursor3d_->GetVisibility() != 0;
  placeCursor(x, y);
  if (wasVisible || cursor3d_->GetVisibility()) window_->Render();
}

void EditWindow::continuePaint(int x, int y) {
  if (paintView_ == PaintView::None) return;
  placeCursor(x, y);
  try {
    if (paintView_ == PaintView::Surface)
      session_.addRays({rayAt(x, y)});
    else
      session_.addPoints({slices_->worldPointAt(paintAxis_, x, y)});
  } catch (const std::exception& e) {
    showMessage(e.what(), true);
    endPaint();
    return;
  }
  updateSlices();
  // One draft at a time: while one renders, the dabs wait for the timer to ask for the
  // next, so the UI thread copies the set at most once per draft frame.
  if (!session_.previewBusy(PreviewQuality::Draft)) requestPreview(PreviewQuality::Draft);
  pollPreview();
  window_->Render();
}

void EditWindow::endPaint() {
  if (paintView_ == PaintView::None) return;
  paintView_ = PaintView::None;
  slices_->holdRange(false);
  std::optional<StrokeResult> result;
  try {
    result = session_.endStroke();
  } catch (const std::exception& e) {
    showMessage(e.what(), true);
  }
  afterChange(result, "stroke");
}

void EditWindow::afterChange(const std::optional<StrokeResult>& result, const char* what) {
  lastChange_ = std::chrono::steady_clock::now();
  updateSlices();
  requestPreview(PreviewQuality::Full);
  pollPreview();
  if (result) {
    char text[160];
    std::snprintf(text, sizeof text, "%s: %zu voxels changed", what, result->voxelsChanged);
    showMessage(text, false);
  }
  maybeAutosave(true);
  updateStatus();
  window_->Render();
}

void EditWindow::cameraMoved() {
  vtkCamera* c = view3d_->GetActiveCamera();
  Camera camera = session_.previewCamera();
  double v[3];
  c->GetPosition(v);
  camera.position = glm::dvec3(v[0], v[1], v[2]);
  c->GetFocalPoint(v);
  camera.target = glm::dvec3(v[0], v[1], v[2]);
  c->GetViewUp(v);
  camera.up = glm::dvec3(v[0], v[1], v[2]);
  camera.fovYDeg = c->GetViewAngle();
  session_.setPreviewCamera(camera);
  refresh();
}

bool EditWindow::moveSliceAt(int x, int y, int steps) {
  const std::optional<int> axis = slices_->axisOf(rendererAt(x, y));
  if (!axis) return false;
  slices_->moveSlice(*axis, steps);
  updateSlices();
  window_->Render();
  return true;
}

void EditWindow::save(bool replaceConfirmed) {
  std::string why;
  if (saveFile(replaceConfirmed, &why) == FileOutcome::NeedsConfirmation) {
    saveArmed_ = true;
    showMessage(why + "\nCtrl+S again replaces it; Ctrl+Shift+S saves as another file", true);
  }
}

void EditWindow::maybeAutosave(bool strokeJustEnded) {
  if (recoveryPending_ || !session_.autosaveStale()) return;
  const double idleSeconds = msSince(lastChange_) / 1000.0;
  if (!(options_.autosaveSeconds <= 0.0 && strokeJustEnded) && idleSeconds < options_.autosaveSeconds) return;
  try {
    session_.autosave();
  } catch (const std::exception& e) {
    showMessage(std::string("autosave failed: ") + e.what(), true);
  }
}

void EditWindow::onTimer() {
  // A dab that came while the last draft rendered asks for the next one here.
  if (painting() && session_.previewStale(PreviewQuality::Draft) && !session_.previewBusy(PreviewQuality::Draft))
    requestPreview(PreviewQuality::Draft);
  if (pollPreview()) window_->Render();
  if (painting()) return;
  if (previewMain_) {
    // A resized window changes the 3D view's aspect: the next frame follows it.
    matchPreviewAspect();
    if (session_.previewStale()) requestPreview(PreviewQuality::Full);
  }
  maybeAutosave(false);
}

void EditWindow::onClose() {
  if (quit_ && quitArmed_) {
    // The user chose to quit without saving: the recovery file would only resurrect it.
    try {
      session_.discardRecovery();
    } catch (const std::exception&) {
    }
    return;
  }
  if (!session_.unsaved() && !recoveryPending_) {
    // Saved (or undone back to the saved state): an older recovery file would only offer
    // to bring back something the user walked away from.
    try {
      session_.discardRecovery();
    } catch (const std::exception&) {
    }
    return;
  }
  if (session_.unsaved() && !recoveryPending_) {
    try {
      session_.autosave();
      std::fprintf(stderr, "sslpv edit: unsaved changes kept in %s; the next `sslpv edit %s` offers to recover them\n",
                   session_.paths().recovery.string().c_str(), session_.paths().scene.string().c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sslpv edit: could not keep the unsaved changes: %s\n", e.what());
    }
  }
}

}  // namespace sslpv
