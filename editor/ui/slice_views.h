#pragma once
// Three axis-aligned slices through the object's material field, shown both inside the 3D
// view and in their own 2D views, with one colour legend. The slices are sampled from the
// same MaterialField every consumer uses (docs/design.md §4), in world space, so
// what the artist sees is what the renderer resamples.
#include <vtkSmartPointer.h>

#include <array>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "editor/legend_range.h"
#include "volume/material/material_field.h"
#include "volume/scene/mesh.h"

class vtkActor;
class vtkColorTransferFunction;
class vtkCutter;
class vtkImageActor;
class vtkImageData;
class vtkPlane;
class vtkPolyData;
class vtkRenderer;
class vtkScalarBarActor;

namespace sslpv {

class SliceViews {
 public:
  /// `views[a]` shows the slice across world axis a; `view3d` also gets all three slices,
  /// the legend and the mesh outlines. `samplesAlongLongest` sets the slices' pixel size.
  SliceViews(const Bounds& worldBounds, vtkPolyData* worldMesh, vtkRenderer* view3d,
             const std::array<vtkRenderer*, 3>& views, int samplesAlongLongest);
  ~SliceViews();

  /// Resamples the three slices of `channel` ("sigma_t", "sigma_s", "g", "albedo"; σ shown
  /// as the mean of RGB per scene unit) and rescales the legend to their range (unless held).
  void update(const MaterialField& field, const std::string& channel, const std::string& units);
  /// During a stroke: update() keeps the colour range (editor/legend_range.h).
  void holdRange(bool on) { range_.hold(on); }
  /// The user's fixed colour range (the panel's "lock range"); update() then never refits.
  LegendRange& range() { return range_; }
  const LegendRange& range() const { return range_; }

  /// Shows or hides the slices and the legend inside the 3D view (the 2D views keep theirs).
  void setVisibleIn3d(bool on);
  /// The slice axis that `renderer` shows, if it is one of the slice views.
  std::optional<int> axisOf(const vtkRenderer* renderer) const;
  /// The world point on slice `axis` under display position (x, y) of its view.
  glm::dvec3 worldPointAt(int axis, int displayX, int displayY) const;
  /// Moves slice `axis` by `steps` sample spacings, within the bounds.
  void moveSlice(int axis, int steps);
  double slicePosition(int axis) const { return position_[axis]; }
  /// Points the 2D views' cameras at their slices (after a resize).
  void resetCameras();

 private:
  void placeSlice(int axis);

  Bounds bounds_;
  double spacing_ = 1.0;
  std::array<double, 3> position_{};
  std::array<vtkRenderer*, 3> views_{};
  std::array<vtkSmartPointer<vtkImageData>, 3> images_;
  std::array<vtkSmartPointer<vtkImageActor>, 3> actors3d_, actors2d_;
  std::array<vtkSmartPointer<vtkPlane>, 3> planes_;
  std::array<vtkSmartPointer<vtkCutter>, 3> cutters_;
  std::array<vtkSmartPointer<vtkActor>, 3> outlines_;
  vtkSmartPointer<vtkColorTransferFunction> colors_;
  vtkSmartPointer<vtkScalarBarActor> legend_;
  LegendRange range_;
};

}  // namespace sslpv
