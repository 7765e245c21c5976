#include "editor/ui/main_window.h"

#include <QAction>
#include <QApplication>
#include <QCloseEvent>
#include <QDockWidget>
#include <QElapsedTimer>
#include <QFileDialog>
#include <QFontMetrics>
#include <QKeySequence>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QScrollArea>
#include <QScrollBar>
#include <QStatusBar>
#include <QThread>
#include <QVBoxLayout>
#include <QVTKOpenGLNativeWidget.h>
#include <vtkGenericOpenGLRenderWindow.h>

#include <algorithm>

#include "editor/ui/brush_panel.h"

namespace sslpv {
namespace {

// One line, cut to the label's width: a long error must not push the window wider or
// spill into the views (the whole text is the label's tooltip).
void setLine(QLabel* label, const std::string& text) {
  QString line = QString::fromStdString(text);
  line.replace('\n', "  ");
  label->setToolTip(line);
  label->setText(label->fontMetrics().elidedText(line, Qt::ElideRight, std::max(label->width(), 200)));
}

}  // namespace

EditMainWindow::EditMainWindow(EditSession& session, EditWindowOptions options, int viewWidth, int viewHeight) {
  view_ = new QVTKOpenGLNativeWidget(this);
  renderWindow_ = vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New();
  view_->setRenderWindow(renderWindow_);
  // Fixed until the first layout, so --size is the views' size (scripted events use it).
  view_->setFixedSize(viewWidth, viewHeight);
  setCentralWidget(view_);
  options.host = renderWindow_;
  editor_ = std::make_unique<EditWindow>(session, options);

  panel_ = new BrushPanel(*editor_);
  auto* scroll = new QScrollArea();
  scroll->setWidget(panel_);
  scroll->setWidgetResizable(true);
  // As wide as the panel wants, so nothing is cut off; it scrolls only vertically.
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  scroll->setMinimumWidth(panel_->minimumSizeHint().width() + scroll->verticalScrollBar()->sizeHint().width() + 4);
  auto* dock = new QDockWidget("Brush", this);
  dock->setObjectName("brush");
  dock->setWidget(scroll);
  dock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  addDockWidget(Qt::RightDockWidgetArea, dock);
  buildMenus();
  buildStatusBar();
  editor_->setListeners([this] { onStateChanged(); },
                        [this](const std::string& text, bool error) { onMessage(text, error); });
  onStateChanged();
}

EditMainWindow::~EditMainWindow() = default;

void EditMainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu("&File");
  QAction* save = file->addAction("&Save", this, [this] { this->save(); });
  save->setShortcut(QKeySequence("Ctrl+S"));
  QAction* saveAs = file->addAction("Save &As...", this, [this] {
    const std::filesystem::path& scene = editor_->session().paths().scene;
    // No overwrite question here: the session asks when replacing would lose work.
    const QString path = QFileDialog::getSaveFileName(
        this, "Save the material set as",
        QString::fromStdString((scene.parent_path() / (scene.stem().string() + "_painted.vdb")).string()),
        "OpenVDB material sets (*.vdb)", nullptr, QFileDialog::DontConfirmOverwrite);
    if (!path.isEmpty()) saveAsTo(path.toStdString());
  });
  saveAs->setShortcut(QKeySequence("Ctrl+Shift+S"));
  QAction* exportAction = file->addAction("&Export...", this, [this] {
    const std::filesystem::path& scene = editor_->session().paths().scene;
    const QString path = QFileDialog::getSaveFileName(
        this, "Export a copy of the material set",
        QString::fromStdString((scene.parent_path() / (scene.stem().string() + "_export.vdb")).string()),
        "OpenVDB material sets (*.vdb)");
    if (!path.isEmpty()) exportTo(path.toStdString());
  });
  exportAction->setShortcut(QKeySequence("Ctrl+E"));
  file->addSeparator();
  QAction* quit = file->addAction("&Quit", this, [this] { quitFromMenu(); });
  quit->setShortcut(QKeySequence("Ctrl+Q"));

  QMenu* edit = menuBar()->addMenu("&Edit");
  edit->addAction("&Undo", this, [this] { editor_->undo(); })->setShortcut(QKeySequence("Ctrl+Z"));
  edit->addAction("&Redo", this, [this] { editor_->redo(); })->setShortcuts({QKeySequence("Ctrl+Y"), QKeySequence("Ctrl+Shift+Z")});

  QMenu* view = menuBar()->addMenu("&View");
  view->addAction("SSLPV preview as the 3D view (b)", this,
                  [this] { editor_->setPreviewAsMainView(!editor_->previewAsMainView()); });
  view->addAction("Lock / unlock the slice range (l)", this, [this] {
    if (editor_->sliceRangeLocked())
      editor_->unlockSliceRange();
    else if (const auto range = editor_->sliceRange())
      editor_->lockSliceRange(range->first, range->second);
  });
}

void EditMainWindow::buildStatusBar() {
  auto* lines = new QWidget();
  auto* layout = new QVBoxLayout(lines);
  layout->setContentsMargins(2, 0, 2, 0);
  layout->setSpacing(0);
  messageLabel_ = new QLabel();
  statusLabel_ = new QLabel();
  for (QLabel* label : {messageLabel_, statusLabel_}) {
    // Ignored horizontally: the text never widens the window, it is elided instead.
    label->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
    label->setTextFormat(Qt::PlainText);
    layout->addWidget(label);
  }
  statusBar()->addWidget(lines, 1);
}

void EditMainWindow::onStateChanged() {
  status_ = editor_->statusText();
  setLine(statusLabel_, status_);
  const bool unsaved = editor_->session().unsaved();
  setWindowTitle(QString::fromStdString("sslpv edit - " + editor_->session().paths().scene.filename().string() +
                                        (unsaved ? " *" : "")));
  panel_->sync();
}

void EditMainWindow::onMessage(const std::string& text, bool error) {
  message_ = text;
  messageLabel_->setStyleSheet(error ? "color: #e04040;" : "");
  setLine(messageLabel_, text);
}

std::string EditMainWindow::statusLine() const { return status_; }
std::string EditMainWindow::messageLine() const { return message_; }

bool EditMainWindow::waitUntilReady(double seconds) {
  QElapsedTimer clock;
  clock.start();
  while (!view_->isValid() && clock.elapsed() < seconds * 1000.0) {
    QApplication::processEvents(QEventLoop::AllEvents, 50);
    QThread::msleep(5);
  }
  QApplication::processEvents();
  // The labels have their real width now: cut the lines to it.
  setLine(statusLabel_, status_);
  setLine(messageLabel_, message_);
  return view_->isValid();
}

void EditMainWindow::releaseViewSize() {
  view_->setMinimumSize(320, 240);
  view_->setMaximumSize(QWIDGETSIZE_MAX, QWIDGETSIZE_MAX);
}

bool EditMainWindow::confirm(const QString& title, const std::string& question) {
  return QMessageBox::question(this, title, QString::fromStdString(question),
                               QMessageBox::Yes | QMessageBox::Cancel) == QMessageBox::Yes;
}

void EditMainWindow::save() {
  std::string why;
  if (editor_->saveFile(false, &why) == EditWindow::FileOutcome::NeedsConfirmation &&
      confirm("Replace the material set?", why + "\n\nReplace it anyway? (Save As keeps it.)"))
    editor_->saveFile(true);
}

EditWindow::FileOutcome EditMainWindow::saveAsTo(const std::string& path, bool askBeforeReplacing) {
  std::string why;
  EditWindow::FileOutcome outcome = editor_->saveFileAs(path, false, &why);
  if (outcome == EditWindow::FileOutcome::NeedsConfirmation) {
    if (askBeforeReplacing && confirm("Replace the file?", why + "\n\nReplace it?"))
      outcome = editor_->saveFileAs(path, true);
    else
      editor_->showMessage(why + " (not replaced)", true);
  }
  return outcome;
}

EditWindow::FileOutcome EditMainWindow::exportTo(const std::string& path) { return editor_->exportFile(path); }

void EditMainWindow::quitFromMenu() {
  if (editor_->session().unsaved()) {
    const auto answer = QMessageBox::question(this, "Unsaved changes", "Save the painted material set before quitting?",
                                              QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
    if (answer == QMessageBox::Cancel) return;
    if (answer == QMessageBox::Save) {
      save();
      if (editor_->session().unsaved()) return;  // the save failed or was refused: stay
    } else {
      editor_->quitWithoutSaving();
    }
  }
  close();
}

void EditMainWindow::closeEvent(QCloseEvent* event) {
  // The window manager's close button keeps unsaved work in the recovery file (main()
  // calls EditWindow::onClose after the loop), as before: no question that could be lost.
  event->accept();
}

}  // namespace sslpv
