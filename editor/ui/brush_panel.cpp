#include "editor/ui/brush_panel.h"

#include <QCheckBox>
#include <QColor>
#include <QColorDialog>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/common.hpp>
#include <iterator>
#include <string>

#include "editor/ui/edit_window.h"
#include "volume/material/artist_params.h"

namespace sslpv {
namespace {

constexpr int kSliderSteps = 1000;

// Channels in the keys' cycling order (BrushControls::cycleChannel).
constexpr BrushChannel kChannels[] = {BrushChannel::Colour, BrushChannel::SigmaT,    BrushChannel::SigmaS,
                                      BrushChannel::G,      BrushChannel::AlbedoMfp, BrushChannel::Preset,
                                      BrushChannel::All};
const char* kChannelNames[] = {"colour", "sigma_t", "sigma_s", "g", "albedo + mfp", "preset", "all channels"};
const char* kModeNames[] = {"set", "add", "multiply", "smooth", "erase"};

// Linear reflectance <-> the sRGB value a screen (and QColorDialog) shows.
double toDisplay(double linear) {
  const double v = std::clamp(linear, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}
double toLinear(double display) {
  const double v = std::clamp(display, 0.0, 1.0);
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

QColor displayColour(const glm::dvec3& linear) {
  return QColor::fromRgbF(toDisplay(linear.x), toDisplay(linear.y), toDisplay(linear.z));
}

QString swatchStyle(const glm::dvec3& linear) {
  const QColor c = displayColour(linear);
  // Black or white lettering by the displayed colour's luminance, as the VTK swatch row.
  const bool dark = 0.2126 * c.redF() + 0.7152 * c.greenF() + 0.0722 * c.blueF() <= 0.5;
  return QString("background-color: %1; color: %2; padding: 2px;").arg(c.name(), dark ? "white" : "black");
}

double mean(const glm::dvec3& v) { return (v.x + v.y + v.z) / 3.0; }

// Three significant digits: the panel is read, not copied (the typed prompt keeps six).
std::string compact(const glm::dvec3& v) {
  char text[64];
  if (v.x == v.y && v.y == v.z)
    std::snprintf(text, sizeof text, "%.3g", v.x);
  else
    std::snprintf(text, sizeof text, "%.3g, %.3g, %.3g", v.x, v.y, v.z);
  return text;
}

}  // namespace

BrushPanel::BrushPanel(EditWindow& editor, QWidget* parent) : QWidget(parent), editor_(editor) {
  BrushControls& controls = editor_.controls();
  const Brush brush = controls.brush();
  const std::string units = editor_.session().scene().units;
  auto* outer = new QVBoxLayout(this);
  form_ = new QFormLayout();
  outer->addLayout(form_);

  channel_ = new QComboBox(this);
  for (const char* name : kChannelNames) channel_->addItem(name);
  form_->addRow("Channel", channel_);
  connect(channel_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this](int i) {
    if (syncing_ || i < 0 || i >= int(std::size(kChannels))) return;
    editor_.controls().setChannel(kChannels[i]);
    changed();
  });
  mode_ = new QComboBox(this);
  form_->addRow("Mode", mode_);
  connect(mode_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this](int i) {
    if (syncing_ || i < 0) return;
    editor_.controls().setMode(BrushMode(mode_->itemData(i).toInt()));
    changed();
  });

  colour_ = new QPushButton("Surface colour...", this);
  form_->addRow("Colour", colour_);
  connect(colour_, &QPushButton::clicked, this, [this] {
    const QColor picked = QColorDialog::getColor(displayColour(editor_.controls().artist().colour), this,
                                                 "Brush surface colour");
    if (picked.isValid()) applyColour(picked);
  });
  // Scatter distance: one number scales all three (the ratios, a material's hue of
  // translucency, stay); the label shows all three.
  distance_ = addNumber(("Scatter dist. (" + units + ")").c_str(), 1e-3 * brush.radius, 1e3 * brush.radius, true, 4,
                        [this](double v) {
                          ArtistParams a = editor_.controls().artist();
                          const double m = mean(a.scatterDistance);
                          a.scatterDistance = m > 0.0 ? a.scatterDistance * (v / m) : glm::dvec3(v);
                          if (const std::string problem = editor_.controls().setArtist(a); !problem.empty())
                            editor_.showMessage(problem, true);
                        });
  g_ = addNumber("g (colour)", -kArtistMaxG, kArtistMaxG, false, 2, [this](double v) {
    ArtistParams a = editor_.controls().artist();
    a.g = v;
    if (const std::string problem = editor_.controls().setArtist(a); !problem.empty()) editor_.showMessage(problem, true);
  });
  artistView_ = new QLabel(this);
  artistView_->setWordWrap(true);
  storedView_ = new QLabel(this);
  storedView_->setWordWrap(true);
  form_->addRow("Artist view", artistView_);
  form_->addRow("Stored", storedView_);

  auto* grid = new QGridLayout();
  for (std::size_t i = 0; i < controls.swatches().size(); ++i) {
    auto* button = new QPushButton(QString::fromStdString(controls.swatchName(i)), this);
    button->setStyleSheet(swatchStyle(controls.swatches()[i].colour));
    button->setToolTip("paint " + QString::fromStdString(controls.swatchName(i)) + "'s colour (p / P cycle)");
    grid->addWidget(button, int(i / 4), int(i % 4));
    connect(button, &QPushButton::clicked, this, [this, i] {
      editor_.controls().pickSwatch(i);
      editor_.showMessage("picked " + editor_.controls().swatchName(i), false);
      changed();
    });
    swatches_.push_back(button);
  }
  form_->addRow("Swatches", grid);

  radius_ = addNumber(("Radius (" + units + ")").c_str(), brush.radius / 50.0, brush.radius * 20.0, true, 4,
                      [this](double v) { editor_.controls().setRadius(v); });
  strength_ = addNumber("Strength", 0.0, 1.0, false, 2, [this](double v) { editor_.controls().setStrength(v); });
  depth_ = addNumber(("Depth (" + units + ")").c_str(), 0.0, 5.0 * brush.radius, false, 4,
                     [this](double v) { editor_.controls().setDepth(v); });
  falloff_ = new QComboBox(this);
  for (const char* name : {"constant", "linear", "smooth", "gaussian"}) falloff_->addItem(name);
  form_->addRow("Falloff", falloff_);
  connect(falloff_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this](int i) {
    if (syncing_ || i < 0) return;
    editor_.controls().setFalloff(BrushFalloff(i));
    changed();
  });
  mirror_ = new QComboBox(this);
  for (const char* name : {"off", "x", "y", "z"}) mirror_->addItem(name);
  form_->addRow("Mirror", mirror_);
  connect(mirror_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this](int i) {
    if (syncing_ || i < 0) return;
    editor_.controls().setMirror(i - 1);
    changed();
  });

  // The slices' colour range: fixed by the user so a colour keeps its value.
  lock_ = new QCheckBox("Lock slice range (l)", this);
  rangeMin_ = new QDoubleSpinBox(this);
  rangeMax_ = new QDoubleSpinBox(this);
  for (QDoubleSpinBox* box : {rangeMin_, rangeMax_}) {
    box->setRange(-1e9, 1e9);
    box->setDecimals(4);
    box->setKeyboardTracking(false);
    connect(box, QOverload<double>::of(&QDoubleSpinBox::valueChanged), this, [this] {
      if (!syncing_ && lock_->isChecked()) applyRange();
    });
  }
  auto* range = new QHBoxLayout();
  range->addWidget(rangeMin_);
  range->addWidget(rangeMax_);
  form_->addRow(lock_);
  form_->addRow("Min / max", range);
  connect(lock_, &QCheckBox::toggled, this, [this](bool on) {
    if (syncing_) return;
    if (on)
      applyRange();
    else
      editor_.unlockSliceRange();
    sync();
  });
  previewView_ = new QCheckBox("SSLPV preview as the 3D view (b)", this);
  form_->addRow(previewView_);
  connect(previewView_, &QCheckBox::toggled, this, [this](bool on) {
    if (!syncing_) editor_.setPreviewAsMainView(on);
  });
  outer->addStretch(1);
  sync();
}

BrushPanel::Number BrushPanel::addNumber(const char* label, double lo, double hi, bool log, int decimals,
                                         std::function<void(double)> apply) {
  Number n;
  n.lo = lo;
  n.hi = hi;
  n.log = log;
  n.slider = new QSlider(Qt::Horizontal, this);
  n.slider->setRange(0, kSliderSteps);
  n.spin = new QDoubleSpinBox(this);
  // The spin box takes any usable value; the slider covers the usual range.
  n.spin->setRange(log ? 1e-9 : lo, log ? 1e12 : hi);
  n.spin->setDecimals(decimals);
  n.spin->setKeyboardTracking(false);
  auto* row = new QHBoxLayout();
  row->addWidget(n.slider, 1);
  row->addWidget(n.spin);
  form_->addRow(label, row);
  QSlider* slider = n.slider;
  QDoubleSpinBox* spin = n.spin;
  connect(slider, &QSlider::valueChanged, this, [=](int step) {
    if (syncing_) return;
    const double t = double(step) / kSliderSteps;
    spin->setValue(log ? lo * std::pow(hi / lo, t) : lo + (hi - lo) * t);
  });
  connect(spin, QOverload<double>::of(&QDoubleSpinBox::valueChanged), this, [this, apply](double v) {
    if (syncing_) return;
    apply(v);
    changed();
  });
  return n;
}

void BrushPanel::setNumber(Number& n, double value) {
  n.spin->setValue(value);
  double t = n.log ? std::log(std::max(value, 1e-300) / n.lo) / std::log(n.hi / n.lo) : (value - n.lo) / (n.hi - n.lo);
  if (!std::isfinite(t)) t = 0.0;
  n.slider->setValue(int(std::lround(std::clamp(t, 0.0, 1.0) * kSliderSteps)));
}

bool BrushPanel::applyColour(const QColor& display) {
  if (!display.isValid()) return false;
  BrushControls& controls = editor_.controls();
  ArtistParams a = controls.artist();
  const double top = maxSurfaceColour(controls.ior());
  const glm::dvec3 linear(toLinear(display.redF()), toLinear(display.greenF()), toLinear(display.blueF()));
  a.colour = glm::min(linear, glm::dvec3(top));
  if (const std::string problem = controls.setArtist(a); !problem.empty()) {
    editor_.showMessage(problem, true);
    return false;
  }
  if (a.colour != linear)
    editor_.showMessage("colour limited to " + std::to_string(top) + " per channel: no material behind this ior "
                        "reflects more diffusely",
                        false);
  changed();
  return true;
}

void BrushPanel::changed() {
  editor_.brushChanged();  // its status listener calls sync()
}

void BrushPanel::fillModes() {
  mode_->clear();
  for (BrushMode m : BrushControls::modesOf(editor_.controls().channel()))
    mode_->addItem(kModeNames[int(m)], int(m));
  mode_->setCurrentIndex(mode_->findData(int(editor_.controls().mode())));
}

void BrushPanel::applyRange() {
  if (!editor_.lockSliceRange(rangeMin_->value(), rangeMax_->value())) sync();
}

void BrushPanel::sync() {
  if (syncing_) return;
  syncing_ = true;
  const QSignalBlocker blockers[] = {QSignalBlocker(channel_), QSignalBlocker(mode_), QSignalBlocker(falloff_),
                                     QSignalBlocker(mirror_), QSignalBlocker(lock_), QSignalBlocker(previewView_)};
  BrushControls& controls = editor_.controls();
  const Brush b = controls.brush();
  channel_->setCurrentIndex(int(std::find(std::begin(kChannels), std::end(kChannels), b.channel) - std::begin(kChannels)));
  fillModes();
  falloff_->setCurrentIndex(int(b.falloff));
  mirror_->setCurrentIndex(controls.mirrorAxis() + 1);
  setNumber(radius_, b.radius);
  setNumber(strength_, b.strength);
  setNumber(depth_, b.depth);
  setNumber(distance_, mean(b.artist.scatterDistance));
  setNumber(g_, b.artist.g);
  colour_->setStyleSheet(swatchStyle(b.artist.colour));
  const std::string units = editor_.session().scene().units;
  char g[32];
  std::snprintf(g, sizeof g, "%.3g", b.artist.g);
  artistView_->setText(QString::fromStdString("colour " + compact(b.artist.colour) + "\nscatter distance " +
                                              compact(b.artist.scatterDistance) + " " + units + "\ng " + g));
  const std::string stored = controls.describeStored();
  storedView_->setText(QString::fromStdString(stored.empty() ? "(sigma values: see the status line)" : stored));
  lock_->setChecked(editor_.sliceRangeLocked());
  if (const auto range = editor_.sliceRange()) {
    rangeMin_->setValue(range->first);
    rangeMax_->setValue(range->second);
  }
  previewView_->setChecked(editor_.previewAsMainView());
  syncing_ = false;
}

}  // namespace sslpv
