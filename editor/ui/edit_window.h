#pragma once
// The editor's VTK views, drawn into the render window of the Qt main window's central
// widget (editor/ui/main_window.h): a 3D view of the object with the slices inside it
// (trackball camera), the live SSLPV preview seen through the 3D view's camera (or, toggled,
// as the 3D view itself), three 2D slice views with a colour legend, the swatch row and a
// help overlay. The status line and messages go to listeners (the Qt status bar).
// Painting, keys and files go through EditSession; this class only maps input to it and
// shows its state, so the keys, the mouse and the Qt panel and menus share one code path.
#include <vtkSmartPointer.h>

#include <array>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "editor/brush_controls.h"
#include "editor/edit_session.h"

class vtkActor;
class vtkCellPicker;
class vtkImageActor;
class vtkImageData;
class vtkRenderWindow;
class vtkRenderWindowInteractor;
class vtkRenderer;
class vtkTextActor;
class vtkTexture;

namespace sslpv {

class SliceViews;

struct EditWindowOptions {
  /// The render window to draw into (the Qt widget's, with its interactor); required.
  vtkRenderWindow* host = nullptr;
  double autosaveSeconds = 5.0;  ///< after the last change; 0: after every stroke
  bool offerRecovery = true;     ///< false when --recover/--discard-recovery answered already
};

class EditWindow {
 public:
  EditWindow(EditSession& session, const EditWindowOptions& options);
  ~EditWindow();

  vtkRenderWindow* renderWindow() const;
  vtkRenderWindowInteractor* interactor() const;
  /// Hands a message to the message listener (errors in red there, and on stderr).
  void showMessage(const std::string& text, bool error);
  /// `state`: the brush, the unsaved flag or the range changed (status bar, panel, title);
  /// `message`: showMessage's text.
  void setListeners(std::function<void()> state, std::function<void(const std::string&, bool)> message);
  /// The status line: the brush as BrushControls::describe() says, and the view modes.
  std::string statusText() const;
  BrushControls& controls() { return controls_; }
  const EditSession& session() const { return session_; }
  /// The panel changed the brush: the slices, the cursor and the status follow.
  void brushChanged();

  // Files and history for the menus: the same EditSession rules as the keys (a set
  // sslpv did not write is replaced only when `replaceConfirmed`; every write atomic).
  enum class FileOutcome { Done, NeedsConfirmation, Failed };
  FileOutcome saveFile(bool replaceConfirmed, std::string* why = nullptr);
  FileOutcome saveFileAs(const std::string& path, bool replaceConfirmed, std::string* why = nullptr);
  FileOutcome exportFile(const std::string& path, std::string* why = nullptr);
  void undo();
  void redo();
  /// The user chose to quit without saving (the menu's question): no recovery file is kept.
  void quitWithoutSaving();

  /// The live SSLPV preview as the 3D view: rendered at the view's aspect through its
  /// camera, drawn as its background, the mesh and 3D slices hidden, the cursor on top.
  void setPreviewAsMainView(bool on);
  bool previewAsMainView() const { return previewMain_; }
  /// A fixed slice colour range (the legend stops refitting); false for an empty range.
  bool lockSliceRange(double lo, double hi);
  void unlockSliceRange();
  bool sliceRangeLocked() const;
  /// The range the slices show now (locked or fitted).
  std::optional<std::pair<double, double>> sliceRange() const;
  vtkRenderer* view3d() const;
  /// Requests a preview of the current state if stale, shows a finished one, redraws.
  void refresh();
  /// Waits for the preview frames requested so far and shows the newest (scripted runs:
  /// before a screenshot).
  void settlePreview();
  /// True once the user asked to quit (q / e), after any unsaved-work confirmation.
  bool quitRequested() const { return quit_; }
  /// The window is closing (window manager or quit): keeps unsaved work in the recovery file.
  void onClose();

  // Input, called by the interactor style (editor/ui/edit_input.cpp).
  bool handleKey(const std::string& keySym, bool ctrl, bool shift, char keyCode);
  /// Starts a stroke at display (x, y) if paint mode is on and a paintable view is under it.
  bool beginPaint(int x, int y);
  void continuePaint(int x, int y);
  void endPaint();
  bool painting() const { return paintView_ != PaintView::None; }
  bool is3dView(const vtkRenderer* renderer) const;
  /// The mouse moved without painting: the brush cursor follows it (paint mode only).
  void hover(int x, int y);
  /// The 3D view's camera moved: the preview follows it.
  void cameraMoved();
  void onTimer();
  /// Moves the slice of the view under (x, y) by `steps` samples; false if none there.
  bool moveSliceAt(int x, int y, int steps);

 private:
  enum class PaintView { None, Surface, Slice };
  void buildScene();
  void updateSlices();
  /// Hands the current state to the preview's worker (never waits for the render).
  void requestPreview(PreviewQuality quality);
  /// Shows a finished frame if there is one; keeps the progress note current. True when
  /// something on screen changed.
  bool pollPreview();
  void showFrame(const PreviewFrame& frame);
  void updatePreviewLabel();
  void updateStatus();
  /// Re-reads the 3D view's aspect for the preview (preview-as-main-view only).
  void matchPreviewAspect();
  void afterChange(const std::optional<StrokeResult>& result, const char* what);
  void save(bool replaceConfirmed);
  enum class PromptKind { Export, SaveAs };
  /// Starts typing a path; the prompt starts empty and Enter on empty takes `suggestion`.
  void startPrompt(PromptKind kind);
  bool handlePromptKey(const std::string& keySym, char keyCode);
  // The colour picker (editor/ui/colour_panel.cpp).
  void buildSwatches();
  void updateSwatches();  ///< the brush swatch shows the brush's colour
  /// Picks the swatch under display (x, y); false when there is none.
  bool pickSwatchAt(int x, int y);
  void startColourEntry();
  void showColourEntry();
  void handleColourEntryKey(const std::string& keySym, char keyCode);
  void showPrompt();
  void maybeAutosave(bool strokeJustEnded);
  SurfaceRay rayAt(int x, int y) const;
  /// Shows the brush (a wire sphere of its radius) at the surface or slice point under
  /// (x, y); hides it where there is none.
  void placeCursor(int x, int y);
  vtkRenderer* rendererAt(int x, int y) const;

  EditSession& session_;
  EditWindowOptions options_;
  BrushControls controls_;
  std::unique_ptr<SliceViews> slices_;

  vtkSmartPointer<vtkRenderWindow> window_;
  vtkSmartPointer<vtkRenderWindowInteractor> interactor_;
  vtkSmartPointer<vtkRenderer> view3d_, preview_, overlay_;
  std::array<vtkSmartPointer<vtkRenderer>, 3> sliceViews_;
  vtkSmartPointer<vtkActor> meshActor_;
  vtkSmartPointer<vtkActor> cursor3d_;
  std::array<vtkSmartPointer<vtkActor>, 3> cursorSlice_;
  vtkSmartPointer<vtkCellPicker> picker_;
  vtkSmartPointer<vtkImageData> previewImage_;
  vtkSmartPointer<vtkImageActor> previewActor_;
  vtkSmartPointer<vtkTextActor> help_, previewLabel_;
  vtkSmartPointer<vtkTexture> background_;  ///< the preview as the 3D view's background
  bool previewMain_ = false;
  std::function<void()> stateListener_;
  std::function<void(const std::string&, bool)> messageListener_;
  std::string lastMessage_;
  bool lastMessageError_ = false;
  vtkSmartPointer<vtkTextActor> storedView_;  ///< the colour brush's σ view, beside the swatches

  PaintView paintView_ = PaintView::None;
  int paintAxis_ = 0;
  bool helpVisible_ = false;
  bool quit_ = false;
  bool quitArmed_ = false;
  bool recoveryPending_ = false;
  std::vector<vtkSmartPointer<vtkTextActor>> swatchActors_;  ///< the Jensen swatches, then the brush's
  std::optional<int> colourEntryField_;  ///< typed entry: 0 colour, 1 scatter distance, 2 g
  std::string colourEntryText_;
  std::optional<std::string> prompt_;  ///< export / save-as path being typed
  PromptKind promptKind_ = PromptKind::Export;
  std::string promptSuggestion_;       ///< what Enter on an empty prompt writes
  std::string replaceArmed_;           ///< a path the user was asked about: writing it again replaces it
  bool saveArmed_ = false;             ///< Ctrl+S was refused pending confirmation: the next one replaces
  std::chrono::steady_clock::time_point lastChange_;
  // What the preview shows and what it waits for.
  std::optional<PreviewFrame> shown_;  ///< the frame on screen (its image already uploaded)
  bool fullPending_ = false;           ///< a full frame was requested and has not arrived
  std::chrono::steady_clock::time_point fullRequestedAt_;
  std::string previewLabelText_;
  vtkSmartPointer<vtkTextActor> previewProgress_;  ///< "rendering ..." over the preview
};

}  // namespace sslpv
