// The editor window's colour picker: a row of swatches (the Jensen materials as surface
// colours at the scene's ior, and the brush's own colour) along the bottom of the 3D view,
// picked by clicking or with p / P, and typed entry of colour, scatter distance and g
// (Enter). The values themselves live in BrushControls.
#include <vtkCoordinate.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "editor/ui/edit_window.h"

namespace sslpv {
namespace {

// Swatch row: normalized window coordinates, just above the slice row (which ends at 0.34).
constexpr double kSwatchRowY = 0.345;
constexpr double kSwatchWidth = 0.5 / 12.0;

/// Linear reflectance -> the sRGB value a display shows it as (VTK writes colours as given).
double toDisplay(double linear) {
  const double v = std::clamp(linear, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

void paintSwatch(vtkTextActor* actor, const glm::dvec3& colour) {
  vtkTextProperty* p = actor->GetTextProperty();
  p->SetBackgroundColor(toDisplay(colour.x), toDisplay(colour.y), toDisplay(colour.z));
  p->SetBackgroundOpacity(1.0);
  // Luminance of the displayed colour decides black or white lettering.
  const double luma = 0.2126 * toDisplay(colour.x) + 0.7152 * toDisplay(colour.y) + 0.0722 * toDisplay(colour.z);
  const double ink = luma > 0.5 ? 0.0 : 1.0;
  p->SetColor(ink, ink, ink);
}

}  // namespace

void EditWindow::buildSwatches() {
  const std::vector<ArtistParams>& swatches = controls_.swatches();
  for (std::size_t i = 0; i <= swatches.size(); ++i) {
    auto actor = vtkSmartPointer<vtkTextActor>::New();
    actor->GetTextProperty()->SetFontSize(11);
    actor->GetTextProperty()->SetFontFamilyToCourier();
    actor->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    actor->SetPosition(0.003 + double(i) * kSwatchWidth, kSwatchRowY);
    // The last one is the brush's colour; the others are labelled with their material.
    const std::string label = i < swatches.size() ? controls_.swatchName(i).substr(0, 5) : "brush";
    actor->SetInput(label.c_str());
    if (i < swatches.size()) paintSwatch(actor, swatches[i].colour);
    overlay_->AddViewProp(actor);
    swatchActors_.push_back(actor);
  }
  storedView_ = vtkSmartPointer<vtkTextActor>::New();
  storedView_->GetTextProperty()->SetFontSize(12);
  storedView_->GetTextProperty()->SetFontFamilyToCourier();
  storedView_->GetTextProperty()->SetColor(0.8, 0.8, 0.8);
  storedView_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  storedView_->SetPosition(0.505, kSwatchRowY);
  overlay_->AddViewProp(storedView_);
  updateSwatches();
}

void EditWindow::updateSwatches() {
  if (swatchActors_.empty()) return;
  paintSwatch(swatchActors_.back(), controls_.artist().colour);
  storedView_->SetInput(controls_.describeStored().c_str());
}

bool EditWindow::pickSwatchAt(int x, int y) {
  for (std::size_t i = 0; i + 1 < swatchActors_.size(); ++i) {
    double box[4];  // xmin, xmax, ymin, ymax relative to the actor's position, in pixels
    swatchActors_[i]->GetBoundingBox(overlay_, box);
    const int* at = swatchActors_[i]->GetPositionCoordinate()->GetComputedDisplayValue(overlay_);
    if (x >= at[0] + box[0] && x <= at[0] + box[1] && y >= at[1] + box[2] && y <= at[1] + box[3]) {
      controls_.pickSwatch(i);
      showMessage("picked " + controls_.swatchName(i), false);
      updateSlices();
      updateSwatches();
      updateStatus();
      window_->Render();
      return true;
    }
  }
  return false;
}

void EditWindow::showColourEntry() {
  const int field = *colourEntryField_;
  showMessage(std::string("brush ") + BrushControls::artistFieldName(field) + " (now " +
                  controls_.artistFieldText(field) + (field == 1 ? " " + session_.scene().units : std::string()) +
                  "; Enter keeps it, Esc cancels): " + colourEntryText_ + "_",
              false);
}

void EditWindow::startColourEntry() {
  colourEntryField_ = 0;
  colourEntryText_.clear();
  showColourEntry();
}

void EditWindow::handleColourEntryKey(const std::string& keySym, char keyCode) {
  if (keySym == "Escape") {
    colourEntryField_.reset();
    showMessage("colour entry cancelled", false);
    return;
  }
  if (keySym == "Return" || keySym == "KP_Enter") {
    const int field = *colourEntryField_;
    if (!colourEntryText_.empty()) {
      const std::string problem = controls_.enterArtistField(field, colourEntryText_);
      if (!problem.empty()) {
        // Stay on the field so the value can be corrected.
        colourEntryText_.clear();
        showMessage(problem + " (type another value, Esc cancels)", true);
        return;
      }
    }
    colourEntryText_.clear();
    if (field < 2) {
      colourEntryField_ = field + 1;
      showColourEntry();
    } else {
      colourEntryField_.reset();
      // Enter with nothing typed keeps every field; the brush is the colour one either way.
      controls_.selectColourChannel();
      updateSlices();
      updateSwatches();
      showMessage("brush colour " + controls_.artistFieldText(0) + ", scatter distance " + controls_.artistFieldText(1) +
                      " " + session_.scene().units + ", g " + controls_.artistFieldText(2),
                  false);
    }
    return;
  }
  if (keySym == "BackSpace") {
    if (!colourEntryText_.empty()) colourEntryText_.pop_back();
  } else if (keyCode >= 32 && keyCode < 127 && std::string("0123456789.,-+eE ").find(keyCode) != std::string::npos) {
    colourEntryText_.push_back(keyCode);
  }
  showColourEntry();
}

}  // namespace sslpv
