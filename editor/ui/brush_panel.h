#pragma once
// The editor's "Brush" dock: channel and mode, the colour brush's surface colour (a
// QColorDialog), scatter distance and g beside what the grids will store (σt, σs, g), the
// Jensen swatches, radius, strength, depth, falloff and mirror, and the slices' colour
// range lock. It edits the window's BrushControls, the state the keys edit; sync()
// re-reads it after a key, so the two never disagree. No physics here: the colour is
// inverted to σ by BrushControls / volume/material/artist_params as for typed colours.
#include <QWidget>

#include <functional>
#include <vector>

class QCheckBox;
class QColor;
class QComboBox;
class QDoubleSpinBox;
class QFormLayout;
class QLabel;
class QPushButton;
class QSlider;

namespace sslpv {

class EditWindow;

class BrushPanel : public QWidget {
 public:
  explicit BrushPanel(EditWindow& editor, QWidget* parent = nullptr);

  /// Re-reads the brush and the slice range into the widgets (signals blocked).
  void sync();
  /// What the colour dialog's answer does: `display` is an sRGB colour as a screen shows
  /// it; the brush gets its linear reflectance as surface colour (clamped to what the
  /// scene's ior allows). False, with a message, when the brush refused it.
  bool applyColour(const QColor& display);

  QComboBox* channelBox() const { return channel_; }
  QComboBox* modeBox() const { return mode_; }
  QDoubleSpinBox* radiusBox() const { return radius_.spin; }
  QSlider* radiusSlider() const { return radius_.slider; }
  QDoubleSpinBox* strengthBox() const { return strength_.spin; }
  QDoubleSpinBox* distanceBox() const { return distance_.spin; }
  QDoubleSpinBox* gBox() const { return g_.spin; }
  QDoubleSpinBox* depthBox() const { return depth_.spin; }
  QCheckBox* lockBox() const { return lock_; }
  QDoubleSpinBox* rangeMinBox() const { return rangeMin_; }
  QDoubleSpinBox* rangeMaxBox() const { return rangeMax_; }
  QCheckBox* previewViewBox() const { return previewView_; }
  const std::vector<QPushButton*>& swatchButtons() const { return swatches_; }

 private:
  /// A slider with its numeric spin box; the spin box holds the value, the slider moves
  /// along [lo, hi] (logarithmically when `log`) and follows it.
  struct Number {
    QSlider* slider = nullptr;
    QDoubleSpinBox* spin = nullptr;
    double lo = 0.0, hi = 1.0;
    bool log = false;
  };
  Number addNumber(const char* label, double lo, double hi, bool log, int decimals,
                   std::function<void(double)> apply);
  void setNumber(Number& n, double value);
  void changed();          ///< the brush changed here: the window follows, the panel re-reads
  void fillModes();
  void applyRange();

  EditWindow& editor_;
  QFormLayout* form_ = nullptr;
  QComboBox* channel_ = nullptr;
  QComboBox* mode_ = nullptr;
  QComboBox* falloff_ = nullptr;
  QComboBox* mirror_ = nullptr;
  QPushButton* colour_ = nullptr;
  QLabel* artistView_ = nullptr;
  QLabel* storedView_ = nullptr;
  Number radius_, strength_, distance_, g_, depth_;
  std::vector<QPushButton*> swatches_;
  QCheckBox* lock_ = nullptr;
  QDoubleSpinBox* rangeMin_ = nullptr;
  QDoubleSpinBox* rangeMax_ = nullptr;
  QCheckBox* previewView_ = nullptr;
  bool syncing_ = false;
};

}  // namespace sslpv
