#include "editor/ui/slice_views.h"
#include "volume/material/material_field.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkCutter.h>
#include <vtkFloatArray.h>
#include <vtkImageActor.h>
#include <vtkImageData.h>
#include <vtkImageMapToColors.h>
#include <vtkImageMapper3D.h>
#include <vtkPlane.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace sslpv {
namespace {

// Viridis at five stops (perceptually uniform; readable by colour-blind users).
constexpr double kViridis[5][3] = {
    {0.267, 0.005, 0.329}, {0.231, 0.322, 0.545}, {0.129, 0.569, 0.549}, {0.369, 0.788, 0.384}, {0.993, 0.906, 0.144}};

float channelValue(const MaterialSample& m, const std::string& channel) {
  if (channel == "g") return m.g;
  if (channel == "sigma_s") return (m.sigmaS.x + m.sigmaS.y + m.sigmaS.z) / 3.0f;
  if (channel == "albedo") {
    float sum = 0.0f;
    for (int c = 0; c < 3; ++c) sum += m.sigmaT[c] > 0.0f ? m.sigmaS[c] / m.sigmaT[c] : 0.0f;
    return sum / 3.0f;
  }
  return (m.sigmaT.x + m.sigmaT.y + m.sigmaT.z) / 3.0f;
}

}  // namespace

SliceViews::SliceViews(const Bounds& worldBounds, vtkPolyData* worldMesh, vtkRenderer* view3d,
                       const std::array<vtkRenderer*, 3>& views, int samplesAlongLongest)
    : bounds_(worldBounds), views_(views) {
  const glm::dvec3 extent = worldBounds.extent();
  spacing_ = std::max({extent.x, extent.y, extent.z}) / std::max(samplesAlongLongest, 2);
  if (!(spacing_ > 0.0)) spacing_ = 1.0;
  for (int a = 0; a < 3; ++a) position_[a] = 0.5 * (worldBounds.min[a] + worldBounds.max[a]);

  colors_ = vtkSmartPointer<vtkColorTransferFunction>::New();
  legend_ = vtkSmartPointer<vtkScalarBarActor>::New();
  legend_->SetLookupTable(colors_);
  legend_->SetNumberOfLabels(4);
  legend_->SetWidth(0.1);
  legend_->SetHeight(0.45);
  legend_->SetPosition(0.8, 0.08);
  legend_->GetTitleTextProperty()->SetFontSize(13);
  legend_->SetUnconstrainedFontSize(true);
  legend_->GetLabelTextProperty()->SetFontSize(11);
  view3d->AddViewProp(legend_);

  for (int a = 0; a < 3; ++a) {
    images_[a] = vtkSmartPointer<vtkImageData>::New();
    auto toColors = vtkSmartPointer<vtkImageMapToColors>::New();
    toColors->SetInputData(images_[a]);
    toColors->SetLookupTable(colors_);
    toColors->SetOutputFormatToRGB();
    actors3d_[a] = vtkSmartPointer<vtkImageActor>::New();
    actors2d_[a] = vtkSmartPointer<vtkImageActor>::New();
    actors3d_[a]->GetMapper()->SetInputConnection(toColors->GetOutputPort());
    actors2d_[a]->GetMapper()->SetInputConnection(toColors->GetOutputPort());
    actors3d_[a]->SetOpacity(0.6);
    view3d->AddViewProp(actors3d_[a]);
    views_[a]->AddViewProp(actors2d_[a]);

    // The object's outline where the slice cuts it, so painting on a slice can aim.
    planes_[a] = vtkSmartPointer<vtkPlane>::New();
    glm::dvec3 normal(0.0);
    normal[a] = 1.0;
    planes_[a]->SetNormal(normal.x, normal.y, normal.z);
    cutters_[a] = vtkSmartPointer<vtkCutter>::New();
    cutters_[a]->SetInputData(worldMesh);
    cutters_[a]->SetCutFunction(planes_[a]);
    auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    mapper->SetInputConnection(cutters_[a]->GetOutputPort());
    mapper->ScalarVisibilityOff();
    outlines_[a] = vtkSmartPointer<vtkActor>::New();
    outlines_[a]->SetMapper(mapper);
    outlines_[a]->GetProperty()->SetColor(1.0, 1.0, 1.0);
    outlines_[a]->GetProperty()->SetLineWidth(2.0f);
    // Lifted towards the 2D view's camera so the line is never hidden by the image.
    outlines_[a]->SetPosition(0.05 * spacing_ * normal.x, 0.05 * spacing_ * normal.y, 0.05 * spacing_ * normal.z);
    views_[a]->AddViewProp(outlines_[a]);
    views_[a]->SetBackground(0.12, 0.12, 0.14);
    placeSlice(a);
  }
  resetCameras();
}

SliceViews::~SliceViews() = default;

void SliceViews::placeSlice(int axis) {
  // The image spans the bounds across the other two axes, one sample thick along `axis`.
  int dims[3];
  double origin[3];
  for (int c = 0; c < 3; ++c) {
    if (c == axis) {
      dims[c] = 1;
      origin[c] = position_[c];
    } else {
      dims[c] = std::max(2, int(std::ceil((bounds_.max[c] - bounds_.min[c]) / spacing_)) + 1);
      origin[c] = 0.5 * (bounds_.min[c] + bounds_.max[c]) - 0.5 * (dims[c] - 1) * spacing_;
    }
  }
  vtkImageData* image = images_[axis];
  image->SetDimensions(dims);
  image->SetOrigin(origin);
  image->SetSpacing(spacing_, spacing_, spacing_);
  if (!image->GetPointData()->GetScalars()) image->AllocateScalars(VTK_FLOAT, 1);
  planes_[axis]->SetOrigin(origin[0], origin[1], origin[2]);
  // The actor shows the slice its display extent spans; by default that is an XY slice,
  // which for the x and y slices would be a single line.
  for (vtkImageActor* actor : {actors3d_[axis].Get(), actors2d_[axis].Get()})
    actor->SetDisplayExtent(0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1);
}

void SliceViews::update(const MaterialField& field, const std::string& channel, const std::string& units) {
  const MaterialField::Sampler sampler = field.sampler();
  double lo = 1e300, hi = -1e300;
  for (int a = 0; a < 3; ++a) {
    placeSlice(a);
    vtkImageData* image = images_[a];
    // Re-allocated every time: the dimensions may not change, but allocation is cheap and
    // keeps the scalars the size the dimensions say.
    image->AllocateScalars(VTK_FLOAT, 1);
    int dims[3];
    double origin[3];
    image->GetDimensions(dims);
    image->GetOrigin(origin);
    auto* values = static_cast<float*>(image->GetScalarPointer());
    std::size_t n = 0;
    for (int k = 0; k < dims[2]; ++k)
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i) {
          const glm::dvec3 p(origin[0] + i * spacing_, origin[1] + j * spacing_, origin[2] + k * spacing_);
          const float v = channelValue(sampler.sample(p), channel);
          values[n++] = v;
          lo = std::min(lo, double(v));
          hi = std::max(hi, double(v));
        }
    image->Modified();
  }
  std::tie(lo, hi) = range_.fit(channel, lo, hi);
  colors_->RemoveAllPoints();
  for (int s = 0; s < 5; ++s)
    colors_->AddRGBPoint(lo + (hi - lo) * s / 4.0, kViridis[s][0], kViridis[s][1], kViridis[s][2]);
  const std::string title = channel == "g" || channel == "albedo" ? channel : channel + " /" + units;
  legend_->SetTitle(title.c_str());
}

void SliceViews::setVisibleIn3d(bool on) {
  for (int a = 0; a < 3; ++a) actors3d_[a]->SetVisibility(on);
}

std::optional<int> SliceViews::axisOf(const vtkRenderer* renderer) const {
  for (int a = 0; a < 3; ++a)
    if (views_[a] == renderer) return a;
  return std::nullopt;
}

glm::dvec3 SliceViews::worldPointAt(int axis, int displayX, int displayY) const {
  vtkRenderer* view = views_[axis];
  view->SetDisplayPoint(displayX, displayY, 0.0);
  view->DisplayToWorld();
  double world[4];
  view->GetWorldPoint(world);
  glm::dvec3 p(world[0], world[1], world[2]);
  if (world[3] != 0.0) p /= world[3];
  p[axis] = position_[axis];
  return p;
}

void SliceViews::moveSlice(int axis, int steps) {
  position_[axis] = std::clamp(position_[axis] + steps * spacing_, bounds_.min[axis], bounds_.max[axis]);
  placeSlice(axis);
}

void SliceViews::resetCameras() {
  // Looking down each axis with the other two as the screen's axes (x right, y up where
  // possible), parallel projection: a slice is a map, not a perspective picture.
  const glm::dvec3 ups[3] = {{0, 1, 0}, {0, 0, -1}, {0, 1, 0}};
  const glm::dvec3 centre = 0.5 * (bounds_.min + bounds_.max);
  for (int a = 0; a < 3; ++a) {
    vtkCamera* camera = views_[a]->GetActiveCamera();
    camera->ParallelProjectionOn();
    glm::dvec3 eye = centre;
    eye[a] += 10.0 * std::max(1.0, glm::length(bounds_.extent()));
    camera->SetFocalPoint(centre.x, centre.y, centre.z);
    camera->SetPosition(eye.x, eye.y, eye.z);
    camera->SetViewUp(ups[a].x, ups[a].y, ups[a].z);
    double b[6] = {bounds_.min.x, bounds_.max.x, bounds_.min.y, bounds_.max.y, bounds_.min.z, bounds_.max.z};
    views_[a]->ResetCamera(b);
    camera->SetParallelScale(camera->GetParallelScale() * 0.75);
  }
}

}  // namespace sslpv
