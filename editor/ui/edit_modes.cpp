// The editor window's view modes: the live SSLPV preview as the 3D view (issue 28: "see
// the paint where you paint") and the slices' user-fixed colour range.
#include <vtkActor.h>
#include <vtkImageData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTexture.h>

#include "editor/ui/edit_window.h"
#include "editor/ui/slice_views.h"

namespace sslpv {

void EditWindow::setPreviewAsMainView(bool on) {
  previewMain_ = on;
  if (!background_) {
    background_ = vtkSmartPointer<vtkTexture>::New();
    background_->SetInputData(previewImage_);
    background_->InterpolateOn();
  }
  // The preview frame fills the 3D view: its pixels are the view's, because it is rendered
  // at the view's aspect through the view's camera (same vertical field of view).
  view3d_->SetBackgroundTexture(background_);
  view3d_->SetTexturedBackground(on);
  // The mesh and the 3D slices would hide the paint; the cursor stays on top.
  meshActor_->SetVisibility(!on);
  slices_->setVisibleIn3d(!on);
  matchPreviewAspect();
  if (!on) {
    // The preview view on the right shows the scene camera's aspect again.
    const Camera& scene = session_.scene().camera;
    session_.setPreviewAspect(double(scene.width) / double(scene.height));
  }
  showMessage(on ? "3D view: the live SSLPV preview (b: back to the mesh)" : "3D view: the mesh and slices", false);
  // The camera may have moved since the last frame; cameraMoved() renders and redraws.
  cameraMoved();
}

void EditWindow::matchPreviewAspect() {
  if (!previewMain_) return;
  const int* size = view3d_->GetSize();
  if (size[0] > 0 && size[1] > 0) session_.setPreviewAspect(double(size[0]) / double(size[1]));
}

bool EditWindow::lockSliceRange(double lo, double hi) {
  if (!slices_->range().lock(lo, hi)) {
    showMessage("slice range: the minimum must be below the maximum, both finite", true);
    return false;
  }
  updateSlices();
  updateStatus();
  window_->Render();
  return true;
}

void EditWindow::unlockSliceRange() {
  slices_->range().unlock();
  updateSlices();
  updateStatus();
  window_->Render();
}

bool EditWindow::sliceRangeLocked() const { return slices_->range().locked(); }

std::optional<std::pair<double, double>> EditWindow::sliceRange() const { return slices_->range().current(); }

vtkRenderer* EditWindow::view3d() const { return view3d_; }

bool EditWindow::is3dView(const vtkRenderer* renderer) const {
  return renderer != nullptr && renderer == view3d_.Get();
}

void EditWindow::brushChanged() {
  const double radius = controls_.brush().radius;
  for (vtkActor* cursor : {cursor3d_.Get(), cursorSlice_[0].Get(), cursorSlice_[1].Get(), cursorSlice_[2].Get()})
    cursor->SetScale(radius);
  updateSlices();
  updateStatus();
  window_->Render();
}

}  // namespace sslpv
