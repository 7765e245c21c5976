#pragma once
// The editor's Qt main window: the VTK views (EditWindow) in a QVTKOpenGLNativeWidget as
// the central widget, the "Brush" dock (BrushPanel), File and Edit menus and a status
// bar, the way ParaView and 3D Slicer host VTK. Every action goes through EditWindow and
// EditSession, the same code the keys use, so the panel, the menus and the keys stay in
// sync and keep the session's safety rules.
#include <QMainWindow>
#include <vtkSmartPointer.h>

#include <memory>
#include <string>

#include "editor/ui/edit_window.h"

class QLabel;
class QVTKOpenGLNativeWidget;
class vtkGenericOpenGLRenderWindow;

namespace sslpv {

class BrushPanel;

class EditMainWindow : public QMainWindow {
 public:
  /// The VTK views start at viewWidth x viewHeight pixels (--size: scripted events and
  /// screenshots use these coordinates); the panel, menus and status bar come on top.
  EditMainWindow(EditSession& session, EditWindowOptions options, int viewWidth, int viewHeight);
  ~EditMainWindow() override;

  EditWindow& editor() { return *editor_; }
  BrushPanel& panel() { return *panel_; }
  QVTKOpenGLNativeWidget* view() const { return view_; }
  /// Waits (processing events) until the views' OpenGL context exists; false after
  /// `seconds` without one.
  bool waitUntilReady(double seconds);
  /// After the first layout: the views may be resized by the user from now on.
  void releaseViewSize();

  // What the menus do after their dialogs (tests call these directly).
  void save();
  /// Save As to `path`; asks before replacing only when the session says it must.
  EditWindow::FileOutcome saveAsTo(const std::string& path, bool askBeforeReplacing = true);
  EditWindow::FileOutcome exportTo(const std::string& path);
  /// The status bar's two lines as shown (tests, screenshots).
  std::string statusLine() const;
  std::string messageLine() const;

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  void buildMenus();
  void buildStatusBar();
  void onStateChanged();
  void onMessage(const std::string& text, bool error);
  void quitFromMenu();
  bool confirm(const QString& title, const std::string& question);

  QVTKOpenGLNativeWidget* view_ = nullptr;
  vtkSmartPointer<vtkGenericOpenGLRenderWindow> renderWindow_;
  std::unique_ptr<EditWindow> editor_;
  BrushPanel* panel_ = nullptr;
  QLabel* statusLabel_ = nullptr;
  QLabel* messageLabel_ = nullptr;
  std::string status_, message_;
};

}  // namespace sslpv
