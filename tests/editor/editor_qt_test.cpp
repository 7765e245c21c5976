// In-process tests of the editor's Qt window (editor/ui/main_window.h, brush_panel.h):
// the panel's and the menus' own code paths (the functions their widgets and dialogs
// call) drive a real window under Xvfb, strokes go through the same entry points the
// mouse uses, and what was painted, saved or shown is checked. The binary re-runs itself
// under xvfb-run when there is no X display; without xvfb-run every test skips, saying so.
#include <gtest/gtest.h>

#include <QApplication>
#include <QColor>
#include <QComboBox>
#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QImage>
#include <QSurfaceFormat>
#include <QVTKOpenGLNativeWidget.h>
#include <vtkRenderer.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

#include "editor/edit_session.h"
#include "editor/ui/brush_panel.h"
#include "editor/ui/edit_input.h"
#include "editor/ui/main_window.h"
#include "test_support.h"
#include "volume/calibration/adding_doubling.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string gSkipReason;  ///< set by main() when no display could be had

// The GUI tests' cube (tests/editor/editor_gui_test.cpp), seen behind ior 1.3.
const char* kScene = R"({
  "units": "mm",
  "mesh": {"primitive": "box", "min": [-5, -5, -5], "max": [5, 5, 5]},
  "material": {"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.0}, "ior": 1.3},
  "lights": [{"type": "directional", "direction": [0, 0, -1], "irradiance": [1, 1, 1]}],
  "camera": {"position": [0, 0, 40], "target": [0, 0, 0], "fov_y_deg": 35, "width": 256, "height": 256},
  "lpv": {"resolution": 16, "steps": 8}
})";

// Views 960x600 as in the scripted tests: the 3D view is x 0..480, y 204..600 (VTK's y up).
constexpr int kWidth = 960, kHeight = 600;

struct Editor {
  TempDir dir;
  fs::path scene = dir / "cube.json";
  std::unique_ptr<EditSession> session;
  std::unique_ptr<EditMainWindow> window;

  Editor() {
    test::writeText(scene, kScene);
    PreviewOptions preview;
    preview.backend = BackendKind::Cpu;
    preview.longestSide = 64;
    session = std::make_unique<EditSession>(scene, preview);
    EditWindowOptions options;
    options.offerRecovery = false;
    window = std::make_unique<EditMainWindow>(*session, options, kWidth, kHeight);
    window->show();
    if (!window->waitUntilReady(30.0)) throw std::runtime_error("no OpenGL context for the views");
    attachEditorInput(window->editor());
    window->editor().refresh();
  }
  EditWindow& edit() { return window->editor(); }
  BrushPanel& panel() { return window->panel(); }
  /// A stroke along the 3D view's centre row, as the mouse would paint it.
  void stroke(int x0 = 200, int x1 = 280, int y = 402) {
    ASSERT_TRUE(edit().beginPaint(x0, y));
    for (int i = 1; i <= 8; ++i) edit().continuePaint(x0 + (x1 - x0) * i / 8, y);
    edit().endPaint();
  }
  void fullStrengthConstant() {
    panel().strengthBox()->setValue(1.0);
    panel().channelBox()->parentWidget();  // the panel exists
    edit().controls().setFalloff(BrushFalloff::Constant);
  }
  std::shared_ptr<const MaterialSet> painted() const { return session->engine().materialSet(); }
};

double toLinear(double display) {
  return display <= 0.04045 ? display / 12.92 : std::pow((display + 0.055) / 1.055, 2.4);
}

TEST(EditorQt, ColourPickedInThePanelPaintsVoxelsThatShowIt) {
  // The colour dialog's answer (an sRGB colour) through BrushPanel::applyColour, a stroke
  // at full strength: every painted voxel shows that colour's linear reflectance behind
  // the scene's ior within 1 % (adding-doubling of the stored σt, σs, g), and the panel's
  // stored view names the σ the brush paints.
  if (!gSkipReason.empty()) GTEST_SKIP() << gSkipReason;
  Editor e;
  e.panel().channelBox()->setCurrentIndex(1);  // sigma_t: the colour pick must switch back
  const QColor picked(179, 77, 26);
  ASSERT_TRUE(e.panel().applyColour(picked));
  EXPECT_EQ(e.edit().controls().brush().channel, BrushChannel::Colour);
  EXPECT_EQ(e.panel().channelBox()->currentIndex(), 0) << "the panel did not follow the brush";
  e.panel().gBox()->setValue(0.3);
  e.fullStrengthConstant();
  const ArtistParams artist = e.edit().controls().artist();
  const glm::dvec3 expected(toLinear(179 / 255.0), toLinear(77 / 255.0), toLinear(26 / 255.0));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(artist.colour[c], expected[c], 1e-6);
  EXPECT_NEAR(artist.g, 0.3, 1e-9);
  e.stroke();
  const auto set = e.painted();
  auto s = set->sigmaS->getConstAccessor();
  auto gs = set->g->getConstAccessor();
  std::size_t voxels = 0;
  for (auto it = set->sigmaT->cbeginValueOn(); it; ++it, ++voxels) {
    const openvdb::Vec3s sigmaT = *it, sigmaS = s.getValue(it.getCoord());
    const double g = gs.getValue(it.getCoord());
    ASSERT_NEAR(g, 0.3, 1e-6);
    for (int c = 0; c < 3; ++c) {
      // The set holds σ per its own unit; the colour does not depend on the unit.
      const double reducedT = sigmaT[c] - sigmaS[c] * g;
      const double rd = addingDoublingHalfSpace(sigmaS[c] * (1.0 - g) / reducedT, 1.3).rd;
      ASSERT_NEAR(rd, expected[c], 0.01 * expected[c]) << it.getCoord() << " channel " << c;
    }
  }
  EXPECT_GT(voxels, 100u);
  EXPECT_NE(e.window->statusLine().find("colour set"), std::string::npos) << e.window->statusLine();
}

/// The largest distance of a painted voxel from `centre` (rest space), and how many.
std::pair<double, std::size_t> paintedReach(const MaterialSet& set, const openvdb::Vec3d& centre) {
  double reach = 0.0;
  std::size_t n = 0;
  for (auto it = set.sigmaT->cbeginValueOn(); it; ++it, ++n)
    reach = std::max(reach, (set.sigmaT->transform().indexToWorld(it.getCoord()) - centre).length());
  return {reach, n};
}

TEST(EditorQt, RadiusFromThePanelIsTheNextStrokesRadius) {
  // One dab at the front face's centre with the radius typed into the panel's spin box,
  // undo, then one with the radius from the panel's slider: each dab reaches as far as
  // its radius (within a voxel) and no further.
  if (!gSkipReason.empty()) GTEST_SKIP() << gSkipReason;
  Editor e;
  e.fullStrengthConstant();
  const double voxel = e.painted()->sigmaT->voxelSize()[0];
  auto dab = [&] {
    EXPECT_TRUE(e.edit().beginPaint(240, 402));
    e.edit().endPaint();
    return paintedReach(*e.painted(), openvdb::Vec3d(0.0, 0.0, 5.0));
  };
  e.panel().radiusBox()->setValue(1.0);
  EXPECT_DOUBLE_EQ(e.edit().controls().brush().radius, 1.0);
  const auto [small, smallCount] = dab();
  EXPECT_LE(small, 1.0 + 1.8 * voxel);
  EXPECT_GE(small, 1.0 - 1.8 * voxel);
  e.edit().undo();
  e.panel().radiusSlider()->setValue(e.panel().radiusSlider()->value() + 200);
  const double radius = e.edit().controls().brush().radius;
  EXPECT_NEAR(e.panel().radiusBox()->value(), radius, 1e-3) << "the spin box follows the slider";
  ASSERT_GT(radius, 2.0) << "the slider step should have grown the radius";
  const auto [large, largeCount] = dab();
  EXPECT_LE(large, radius + 1.8 * voxel);
  EXPECT_GE(large, radius - 1.8 * voxel);
  EXPECT_GT(largeCount, 4 * smallCount);
}

TEST(EditorQt, SaveAsFromTheMenuWritesTheNamedFileAndKeepsTheOriginal) {
  // Save (Ctrl+S's action) writes cube_material.vdb; more paint, then Save As's code path
  // after the file dialog: the named file has the new paint, the first file is byte for
  // byte as saved, and the scene names the new one.
  if (!gSkipReason.empty()) GTEST_SKIP() << gSkipReason;
  Editor e;
  e.stroke();
  e.window->save();
  const fs::path original = e.dir / "cube_material.vdb";
  ASSERT_TRUE(fs::exists(original)) << e.window->messageLine();
  const std::string originalBytes = test::readText(original);
  e.stroke(200, 280, 440);
  const fs::path named = e.dir / "named.vdb";
  EXPECT_EQ(e.window->saveAsTo(named.string(), false), EditWindow::FileOutcome::Done) << e.window->messageLine();
  ASSERT_TRUE(fs::exists(named));
  EXPECT_GT(loadMaterialSet(named)->sigmaT->activeVoxelCount(), loadMaterialSet(original)->sigmaT->activeVoxelCount());
  EXPECT_EQ(test::readText(original), originalBytes) << "Save As changed the original set";
  EXPECT_EQ(loadScene(e.scene).material.vdb.value_or(""), named);
  EXPECT_FALSE(e.session->unsaved());
  EXPECT_NE(e.window->messageLine().find("saved as"), std::string::npos) << e.window->messageLine();
}

TEST(EditorQt, LockedSliceRangeStaysFixedAcrossAStroke) {
  // Unlocked, a σt stroke refits the legend (so the check below can fail); locked from the
  // panel's min / max fields, the next stroke leaves the range exactly as typed.
  if (!gSkipReason.empty()) GTEST_SKIP() << gSkipReason;
  Editor e;
  e.panel().channelBox()->setCurrentIndex(1);  // sigma_t: set 2 x base
  e.fullStrengthConstant();
  const auto before = e.edit().sliceRange();
  ASSERT_TRUE(before);
  e.stroke();
  const auto refitted = e.edit().sliceRange();
  ASSERT_TRUE(refitted);
  EXPECT_NE(*refitted, *before) << "an unlocked range should refit to the painted values";
  e.panel().rangeMinBox()->setValue(0.25);
  e.panel().rangeMaxBox()->setValue(7.5);
  e.panel().lockBox()->setChecked(true);
  ASSERT_TRUE(e.edit().sliceRangeLocked());
  e.edit().controls().setRadius(2.0 * e.edit().controls().brush().radius);
  e.stroke(150, 330, 380);
  EXPECT_EQ(e.edit().sliceRange(), std::make_optional(std::make_pair(0.25, 7.5)));
  EXPECT_NE(e.window->statusLine().find("range locked"), std::string::npos);
  e.panel().lockBox()->setChecked(false);
  EXPECT_NE(e.edit().sliceRange(), std::make_optional(std::make_pair(0.25, 7.5))) << "unlocked: fitted again";
}

TEST(EditorQt, PreviewAsTheMainViewShowsTheRenderedObject) {
  // The panel's toggle: the preview is rendered at the 3D view's aspect and drawn as that
  // view's background with the mesh hidden; the view's centre (the cube's lit face) shows
  // the preview's object, neither the 3D view's background nor the preview's black.
  if (!gSkipReason.empty()) GTEST_SKIP() << gSkipReason;
  Editor e;
  e.panel().previewViewBox()->setChecked(true);
  ASSERT_TRUE(e.edit().previewAsMainView());
  e.edit().settlePreview();
  e.edit().refresh();
  const Camera& camera = e.session->previewCamera();
  EXPECT_NEAR(double(camera.width) / camera.height, 480.0 / 396.0, 0.02) << "not the view's aspect";
  QImage shot = e.window->view()->grabFramebuffer().convertToFormat(QImage::Format_RGB888);
  ASSERT_EQ(shot.width(), kWidth);
  // The 3D view's centre, rows from the top: x 240, y (600 - 402) = 198.
  std::size_t object = 0, total = 0;
  for (int y = 178; y < 218; ++y)
    for (int x = 220; x < 260; ++x, ++total) {
      const QColor c = shot.pixelColor(x, y);
      const bool black = c.red() + c.green() + c.blue() < 15;
      const bool background = std::abs(c.red() - 41) + std::abs(c.green() - 43) + std::abs(c.blue() - 51) < 12;
      if (!black && !background) ++object;
    }
  EXPECT_GT(double(object) / total, 0.9) << "the 3D view's centre does not show the preview's object";
  // Its corner shows the preview's black background, not the 3D view's own (41, 43, 51):
  // the preview is the view's background, not only something drawn inside it.
  std::size_t black = 0, corner = 0;
  for (int y = 20; y < 60; ++y)
    for (int x = 20; x < 60; ++x, ++corner) {
      const QColor c = shot.pixelColor(x, y);
      if (c.red() + c.green() + c.blue() < 15) ++black;
    }
  EXPECT_GT(double(black) / corner, 0.95) << "the 3D view's corner is not the preview's background";
  // A resized window: the next timer tick asks for a frame at the view's new aspect.
  e.window->view()->setFixedSize(kWidth, 400);
  for (int i = 0; i < 20; ++i) QApplication::processEvents();
  e.edit().onTimer();
  const int* size = e.edit().view3d()->GetSize();
  ASSERT_GT(size[1], 0);
  EXPECT_NEAR(double(size[0]) / size[1], 480.0 / (400 * (1.0 - 0.34)), 0.02) << "the view did not resize";
  EXPECT_NEAR(double(e.session->previewCamera().width) / e.session->previewCamera().height,
              double(size[0]) / size[1], 0.03)
      << "the preview did not follow the resized view";
  // Off again: the mesh view is back and the preview keeps the scene camera's aspect.
  e.panel().previewViewBox()->setChecked(false);
  EXPECT_FALSE(e.edit().previewAsMainView());
  EXPECT_EQ(e.session->previewCamera().width, e.session->previewCamera().height);
}

}  // namespace
}  // namespace sslpv

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const bool listing = ::testing::GTEST_FLAG(list_tests);
  const char* display = std::getenv("DISPLAY");
  if (!listing && (display == nullptr || *display == '\0')) {
    if (std::getenv("SSLPV_QT_TEST_UNDER_XVFB") == nullptr &&
        sslpv::test::runProgram({"sh", "-c", "command -v xvfb-run"}).exitCode == 0) {
      // Once, under a private X server (the flag stops a loop if xvfb-run sets no DISPLAY).
      setenv("SSLPV_QT_TEST_UNDER_XVFB", "1", 1);
      std::vector<char*> args{const_cast<char*>("xvfb-run"), const_cast<char*>("-a"), const_cast<char*>("-s"),
                              const_cast<char*>("-screen 0 1280x1024x24")};
      char self[4096];
      const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
      if (n > 0) {
        self[n] = '\0';
        args.push_back(self);
        for (int i = 1; i < argc; ++i) args.push_back(argv[i]);
        args.push_back(nullptr);
        execvp("xvfb-run", args.data());
      }
    }
    sslpv::gSkipReason = "no X display and no xvfb-run (Debian package xvfb): the editor's Qt window needs one";
  }
  std::unique_ptr<QApplication> app;
  if (!listing && sslpv::gSkipReason.empty()) {
    QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
    static int qtArgc = 1;
    static char name[] = "editor_qt_test";
    static char* qtArgv[] = {name, nullptr};
    app = std::make_unique<QApplication>(qtArgc, qtArgv);
  }
  return RUN_ALL_TESTS();
}
