// sslpv-edit: the editor window (`sslpv edit` runs this program). A separate program so
// the command-line tool never loads Qt, VTK and their X11 dependencies.
//
// Scripted use (tests, bug reports): --play replays a vtkInteractorEventRecorder script
// (StreamVersion 1.1) on the views' interactor, --screenshot writes the views afterwards
// (--screenshot-window: the whole Qt window with panel, menus and status bar), --exit
// ends the program then instead of waiting for the user; --record writes the user's
// events as a script.
#include <QApplication>
#include <QImage>
#include <QPixmap>
#include <QSurfaceFormat>
#include <QTimer>
#include <QVTKOpenGLNativeWidget.h>
#include <vtkInteractorEventRecorder.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "editor/edit_session.h"
#include "editor/ui/edit_input.h"
#include "editor/ui/edit_window.h"
#include "editor/ui/main_window.h"
#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
// Last: Xlib's macros (None, Status, Bool) would clash with the headers above.
#include <X11/Xlib.h>

namespace {

using namespace sslpv;

constexpr int kExitInput = 2, kExitResource = 3;

struct Options {
  std::string scene, backend = "vulkan", steps, play, record, screenshot, screenshotWindow, size = "1280x800";
  std::optional<int> grid;
  int previewSize = 256;
  double autosaveSeconds = 5.0;
  bool recover = false, discardRecovery = false, exitAfter = false;
  bool backendGiven = false;  ///< --backend on the command line: no silent fallback
};

// Qt aborts the process (exit 134) when it cannot connect to the display: find out first,
// so a wrong DISPLAY is a one-line error with the resource exit code.
std::string displayProblem() {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0')
    return "no X display (DISPLAY is not set): the editor needs one; run it under xvfb-run for scripted use";
  Display* connection = XOpenDisplay(nullptr);
  if (connection == nullptr)
    return std::string("cannot open the X display '") + display + "': the editor needs one; run it under xvfb-run";
  XCloseDisplay(connection);
  return {};
}

void writeScreenshot(vtkRenderWindow* window, const std::string& file) {
  window->Render();
  auto grab = vtkSmartPointer<vtkWindowToImageFilter>::New();
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  writeAtomically(file, [&](const std::filesystem::path& temp) {
    auto png = vtkSmartPointer<vtkPNGWriter>::New();
    png->SetFileName(temp.c_str());
    png->SetInputConnection(grab->GetOutputPort());
    png->Write();
    if (png->GetErrorCode() != 0 || !std::filesystem::exists(temp))
      throw ResourceError(file + ": could not write the screenshot");
  });
}

std::string readText(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file + ": cannot read the event script");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The start-up error in a window, as well as on stderr: someone who launched the editor
// from a desktop never sees the terminal.
int showStartupError(const Options& options, const std::string& message, int exitCode) {
  std::fprintf(stderr, "sslpv edit: %s\n", message.c_str());
  // Only whether DISPLAY is set: the XOpenDisplay probe right before VTK opens its own
  // connection made this window crash (exit 139) in about 1 of 6 runs under load.
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') return exitCode;
  auto window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetSize(900, 200);
  window->SetWindowName("sslpv edit - cannot open the scene");
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  renderer->SetBackground(0.18, 0.05, 0.05);
  window->AddRenderer(renderer);
  auto text = vtkSmartPointer<vtkTextActor>::New();
  text->SetInput(("sslpv edit cannot open the scene:\n" + message + "\n\n(press q to close)").c_str());
  text->GetTextProperty()->SetFontSize(16);
  text->SetPosition(20, 40);
  renderer->AddViewProp(text);
  auto interactor = vtkSmartPointer<vtkRenderWindowInteractor>::New();
  interactor->SetRenderWindow(window);
  interactor->Initialize();
  window->Render();
  if (!options.screenshot.empty()) writeScreenshot(window, options.screenshot);
  if (!options.exitAfter) interactor->Start();
  return exitCode;
}

int run(const Options& options) {
  int width = 0, height = 0;
  char x = 0;
  std::istringstream size(options.size);
  if (!(size >> width >> x >> height) || x != 'x' || width < 320 || height < 240 || width > 8192 || height > 8192)
    throw InputError("--size: expected WIDTHxHEIGHT of at least 320x240, got '" + options.size + "'");
  if (options.previewSize < 16 || options.previewSize > 4096)
    throw InputError("--preview-size: must be between 16 and 4096");
  if (!(options.autosaveSeconds >= 0.0)) throw InputError("--autosave-seconds: must be >= 0");
  if (options.recover && options.discardRecovery)
    throw InputError("--recover and --discard-recovery: choose one");
  if (!options.screenshot.empty()) requireWritableOutput(options.screenshot);
  const std::string playScript = options.play.empty() ? std::string() : readText(options.play);

  PreviewOptions preview;
  preview.backend = options.backend == "vulkan" ? BackendKind::Vulkan : BackendKind::Cpu;
  preview.longestSide = options.previewSize;
  std::unique_ptr<EditSession> session;
  std::string fallbackNote;
  try {
    const LpvSettings sceneLpv = loadScene(options.scene).lpv;
    preview.lpv = applyLpvFlags(sceneLpv, {options.grid, options.steps, std::nullopt, ""});
    try {
      session = std::make_unique<EditSession>(options.scene, preview);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      // No usable Vulkan device: the preview runs on the CPU backend (same interface,
      // same image within 0.2 %) unless the user asked for Vulkan by name.
      if (preview.backend != BackendKind::Vulkan || options.backendGiven) throw;
      fallbackNote = std::string("Vulkan preview unavailable (") + e.what() + "): previewing on the CPU";
      std::fprintf(stderr, "sslpv edit: %s\n", fallbackNote.c_str());
      preview.backend = BackendKind::Cpu;
      session = std::make_unique<EditSession>(options.scene, preview);
    }
  } catch (const InputError& e) {
    return showStartupError(options, e.what(), kExitInput);
  }
  if (const std::string problem = displayProblem(); !problem.empty()) throw ResourceError(problem);
  if (!options.screenshotWindow.empty()) requireWritableOutput(options.screenshotWindow);

  if (options.recover) session->recover();
  if (options.discardRecovery) session->discardRecovery();

  // The views need an OpenGL 3.2 core context, asked for before the application exists.
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
  int qtArgc = 1;
  char programName[] = "sslpv-edit";
  char* qtArgv[] = {programName, nullptr};
  QApplication app(qtArgc, qtArgv);
  EditWindowOptions windowOptions;
  windowOptions.autosaveSeconds = options.autosaveSeconds;
  windowOptions.offerRecovery = !options.recover && !options.discardRecovery;
  EditMainWindow mainWindow(*session, windowOptions, width, height);
  mainWindow.show();
  if (!mainWindow.waitUntilReady(30.0))
    throw ResourceError("the editor's views got no OpenGL context (3.2 core) from the X display");
  EditWindow& window = mainWindow.editor();
  if (!fallbackNote.empty()) window.showMessage(fallbackNote, false);
  attachEditorInput(window);
  vtkRenderWindowInteractor* interactor = window.interactor();
  window.refresh();

  vtkSmartPointer<vtkInteractorEventRecorder> recorder;
  if (!options.play.empty() || !options.record.empty()) {
    recorder = vtkSmartPointer<vtkInteractorEventRecorder>::New();
    recorder->SetInteractor(interactor);
  }
  if (!options.play.empty()) {
    recorder->ReadFromInputStringOn();
    recorder->SetInputString(playScript.c_str());
    recorder->Play();
    window.refresh();
  }
  if (!options.screenshot.empty()) {
    // A scripted run's picture is of the final state: its preview frame, not whichever
    // draft or earlier frame had arrived when the script ended.
    window.settlePreview();
    writeScreenshot(window.renderWindow(), options.screenshot);
  }
  if (!options.screenshotWindow.empty()) {
    if (options.screenshot.empty()) window.settlePreview();
    window.refresh();
    QApplication::processEvents();
    const QImage shot = mainWindow.grab().toImage();
    writeAtomically(options.screenshotWindow, [&](const std::filesystem::path& temp) {
      if (!shot.save(QString::fromStdString(temp.string()), "PNG"))
        throw ResourceError(options.screenshotWindow + ": could not write the screenshot");
    });
  }
  if (!options.exitAfter && !window.quitRequested()) {
    if (!options.record.empty()) {
      recorder->SetFileName(options.record.c_str());
      recorder->On();
      recorder->Record();
    }
    // Also how finished preview frames reach the screen: 50 ms keeps their delay short
    // (a poll is two uncontended mutex locks). The keys' quit (q, e) ends the loop here.
    QTimer timer;
    QObject::connect(&timer, &QTimer::timeout, [&] {
      window.onTimer();
      if (window.quitRequested()) mainWindow.close();
    });
    timer.start(50);
    // From here the user may resize the views; scripted events above needed --size.
    mainWindow.releaseViewSize();
    QApplication::exec();
    if (recorder) recorder->Stop();
  }
  window.onClose();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Saves and autosaves write temporaries; closing the terminal or Ctrl-C must not leave them.
  sslpv::removeTemporariesOnSignals();
  Options options;
  CLI::App app{"sslpv edit: paint sigma_t, sigma_s and g into a scene's material set with a live SSLPV preview", "sslpv edit"};
  app.add_option("scene", options.scene, "Scene JSON file")->required();
  CLI::Option* backend = app.add_option("--backend", options.backend,
                                        "Preview backend: vulkan (default; the CPU when there is no device) or cpu")
      ->check(CLI::IsMember({"cpu", "vulkan"}));
  app.add_option("--grid", options.grid, "Preview LPV resolution (overrides lpv.resolution)");
  app.add_option("--steps", options.steps, "Preview propagation steps, or 'auto' (overrides lpv.steps)");
  app.add_option("--preview-size", options.previewSize, "Longest side of the preview image in pixels");
  app.add_option("--size", options.size, "Window size WIDTHxHEIGHT");
  app.add_option("--autosave-seconds", options.autosaveSeconds,
                 "Write the recovery file this long after the last change (0: after every stroke)");
  app.add_flag("--recover", options.recover, "Recover unsaved work of an earlier session without asking");
  app.add_flag("--discard-recovery", options.discardRecovery, "Delete unsaved work of an earlier session");
  app.add_option("--play", options.play, "Replay a vtkInteractorEventRecorder event script after start-up");
  app.add_option("--record", options.record, "Record this session's events to a script");
  app.add_option("--screenshot", options.screenshot, "Write the views as PNG after start-up (and --play)");
  app.add_option("--screenshot-window", options.screenshotWindow,
                 "Write the whole window (panel, menus, status bar) as PNG after start-up (and --play)");
  app.add_flag("--exit", options.exitAfter, "Exit after --play/--screenshot instead of waiting for the user");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::fprintf(stderr, "sslpv edit: %s (see sslpv edit --help)\n", e.what());
    return kExitInput;
  }
  options.backendGiven = backend->count() > 0;
  try {
    return run(options);
  } catch (const InputError& e) {
    std::fprintf(stderr, "sslpv edit: %s\n", e.what());
    return kExitInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sslpv edit: %s\n", e.what());
    return kExitResource;
  }
}
