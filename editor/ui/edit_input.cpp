// Mouse and keyboard of the editor window: a trackball camera style that hands painting,
// the editor's keys and slice scrolling to EditWindow and keeps VTK's camera behaviour
// for everything else.
#include "editor/ui/edit_input.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkObjectFactory.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>

#include <cstring>
#include <string>

#include "editor/ui/edit_window.h"

namespace sslpv {
namespace {

class EditorStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static EditorStyle* New();
  vtkTypeMacro(EditorStyle, vtkInteractorStyleTrackballCamera)

  EditWindow* window = nullptr;

  void OnLeftButtonDown() override {
    const int* p = Interactor->GetEventPosition();
    if (window->beginPaint(p[0], p[1])) return;
    // Rotating a slice view would turn its map sideways: left drag there does nothing.
    FindPokedRenderer(p[0], p[1]);
    if (!window->is3dView(CurrentRenderer)) return;
    Superclass::OnLeftButtonDown();
  }
  void OnLeftButtonUp() override {
    if (window->painting()) {
      window->endPaint();
      return;
    }
    Superclass::OnLeftButtonUp();
  }
  void OnMouseMove() override {
    const int* p = Interactor->GetEventPosition();
    if (window->painting()) {
      window->continuePaint(p[0], p[1]);
      return;
    }
    Superclass::OnMouseMove();
    // Not while the camera moves: the picking would slow the rotation down.
    if (State == VTKIS_NONE) window->hover(p[0], p[1]);
  }
  void OnMouseWheelForward() override { wheel(+1); }
  void OnMouseWheelBackward() override { wheel(-1); }

  // Camera interactions end here; the preview follows the 3D view's camera.
  void EndRotate() override {
    Superclass::EndRotate();
    cameraMoved();
  }
  void EndPan() override {
    Superclass::EndPan();
    cameraMoved();
  }
  void EndDolly() override {
    Superclass::EndDolly();
    cameraMoved();
  }
  void EndSpin() override {
    Superclass::EndSpin();
    cameraMoved();
  }

  void OnKeyPress() override {
    const char* sym = Interactor->GetKeySym();
    const std::string key = sym ? sym : "";
    const int* p = Interactor->GetEventPosition();
    handledByEditor_ = false;
    if (key == "Up" || key == "Down" || key == "Prior" || key == "Next") {
      const int steps = (key == "Up" || key == "Prior") ? 1 : -1;
      handledByEditor_ = window->moveSliceAt(p[0], p[1], key == "Prior" || key == "Next" ? 8 * steps : steps);
    } else {
      handledByEditor_ = window->handleKey(key, Interactor->GetControlKey() != 0, Interactor->GetShiftKey() != 0,
                                           Interactor->GetKeyCode());
    }
    if (window->quitRequested()) Interactor->TerminateApp();
  }
  void OnChar() override {
    if (handledByEditor_) {
      handledByEditor_ = false;
      return;
    }
    // VTK's camera keys stay; its quit keys (q, e) go through the editor's unsaved check,
    // and the other defaults (pick, joystick, stereo) do not apply to this window.
    switch (Interactor->GetKeyCode()) {
      case 'r':
      case 'R':
        Superclass::OnChar();
        cameraMoved();
        break;
      case 'f':
      case 'F':
      case 'w':
      case 'W':
      case 's':
      case 'S':
      case '3':
        Superclass::OnChar();
        break;
      default:
        break;
    }
  }

 private:
  void wheel(int direction) {
    const int* p = Interactor->GetEventPosition();
    if (window->moveSliceAt(p[0], p[1], direction)) return;
    FindPokedRenderer(p[0], p[1]);
    if (direction > 0)
      Superclass::OnMouseWheelForward();
    else
      Superclass::OnMouseWheelBackward();
    if (window->is3dView(CurrentRenderer)) window->cameraMoved();
  }
  void cameraMoved() {
    if (window->is3dView(CurrentRenderer)) window->cameraMoved();
  }

  bool handledByEditor_ = false;
};

vtkStandardNewMacro(EditorStyle);

void onTimer(vtkObject*, unsigned long, void* clientData, void*) {
  static_cast<EditWindow*>(clientData)->onTimer();
}

void onExit(vtkObject* caller, unsigned long, void*, void*) {
  // The window manager's close button: end the event loop; main() then runs onClose().
  static_cast<vtkRenderWindowInteractor*>(caller)->TerminateApp();
}

}  // namespace

void attachEditorInput(EditWindow& window) {
  vtkRenderWindowInteractor* interactor = window.interactor();
  auto style = vtkSmartPointer<EditorStyle>::New();
  style->window = &window;
  interactor->SetInteractorStyle(style);

  auto timer = vtkSmartPointer<vtkCallbackCommand>::New();
  timer->SetCallback(onTimer);
  timer->SetClientData(&window);
  interactor->AddObserver(vtkCommand::TimerEvent, timer);
  auto exit = vtkSmartPointer<vtkCallbackCommand>::New();
  exit->SetCallback(onExit);
  interactor->AddObserver(vtkCommand::ExitEvent, exit);
}

}  // namespace sslpv
