// GUI tests of the editor window: `sslpv edit` under Xvfb plays back recorded interaction
// (vtkInteractorEventRecorder scripts written here), then the saved material set and a
// screenshot are checked. Skips loudly where the editor was not built (no VTK) or
// xvfb-run is missing.
//
// Views 960x600 (--size; the Qt window's panel, menus and status bar come on top): the 3D
// view covers x 0..480, y 204..600 (VTK's y goes up), the three slice views x 0..320,
// 320..640, 640..960 at y 0..204 (slices across x, y, z; the status line that took y 0..30
// is the Qt status bar now).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "editor/brush_engine.h"
#include "test_support.h"
#include "volume/calibration/adding_doubling.h"
#include "volume/core/image_io.h"
#include "volume/scene/material.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using test::RunResult;
using test::TempDir;

// A 10 mm cube of a marble-like base, lit and seen from +z (the 3D view's centre ray hits
// the front face's centre).
const char* kScene = R"({
  "units": "mm",
  "mesh": {"primitive": "box", "min": [-5, -5, -5], "max": [5, 5, 5]},
  "material": {"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.0}},
  "lights": [{"type": "directional", "direction": [0, 0, -1], "irradiance": [1, 1, 1]}],
  "camera": {"position": [0, 0, 40], "target": [0, 0, 0], "fov_y_deg": 35, "width": 256, "height": 256},
  "lpv": {"resolution": 16, "steps": 8}
})";

class EventScript {
 public:
  EventScript() { text_ << "# StreamVersion 1.1\n"; }
  EventScript& drag(int x0, int y0, int x1, int y1, int steps) {
    event("MouseMoveEvent", x0, y0);
    event("LeftButtonPressEvent", x0, y0);
    for (int i = 1; i <= steps; ++i)
      event("MouseMoveEvent", x0 + (x1 - x0) * i / steps, y0 + (y1 - y0) * i / steps);
    event("LeftButtonReleaseEvent", x1, y1);
    return *this;
  }
  /// A key as X11 delivers it: press, char, release (modifiers: 1 shift, 2 control).
  EventScript& key(const std::string& keySym, int keyCode, int modifiers = 0) {
    for (const char* name : {"KeyPressEvent", "CharEvent", "KeyReleaseEvent"})
      text_ << name << " 240 402 " << modifiers << " " << keyCode << " 1 " << keySym << "\n";
    return *this;
  }
  EventScript& ctrl(char letter) { return key(std::string(1, letter), letter - 'a' + 1, 2); }
  /// Typed text of digits, '.', ',' and '-', then Enter.
  EventScript& type(const std::string& text) {
    for (char c : text) {
      const std::string sym = c == '.' ? "period" : c == ',' ? "comma" : c == '-' ? "minus" : std::string(1, c);
      key(sym, c);
    }
    return key("Return", 13);
  }
  EventScript& click(int x, int y) { return drag(x, y, x, y, 0); }
  /// Types `text` into a prompt, one key per character (the window reads the key code).
  EventScript& typePath(const std::string& text) {
    for (char c : text) key(std::isalnum(static_cast<unsigned char>(c)) ? std::string(1, c) : "Typed", c);
    return *this;
  }
  EventScript& enter() { return key("Return", 13); }
  EventScript& wheelForward(int x, int y, int times) {
    for (int i = 0; i < times; ++i) event("MouseWheelForwardEvent", x, y);
    return *this;
  }
  std::string str() const { return text_.str(); }

 private:
  void event(const char* name, int x, int y) { text_ << name << " " << x << " " << y << " 0 0 0 0\n"; }
  std::ostringstream text_;
};

std::string editorSkipReason() {
#ifndef SSLPV_EDIT_BINARY
  return "the editor (sslpv-edit) was not built: VTK was not found at configure time";
#else
  if (test::runProgram({"sh", "-c", "command -v xvfb-run"}).exitCode != 0)
    return "xvfb-run is not installed (Debian package xvfb): the editor needs an X display";
  return {};
#endif
}

RunResult runEditor(const std::vector<std::string>& args) {
  std::vector<std::string> command{"xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", SSLPV_BINARY, "edit"};
  command.insert(command.end(), args.begin(), args.end());
  return test::runProgram(command);
}

struct Project {
  TempDir dir;
  fs::path scene = dir / "cube.json";
  fs::path events = dir / "events.txt";
  fs::path saved = dir / "cube_material.vdb";
  fs::path recovery = dir / "cube.json.recovery.vdb";
  Project() { test::writeText(scene, kScene); }
};

std::size_t activeVoxels(const fs::path& vdb) {
  return std::size_t(loadMaterialSet(vdb)->sigmaT->activeVoxelCount());
}

// Both images 8-bit sRGB from PNG; thresholds on display values (0..255).
struct ImageDifference {
  double meanAbs = 0.0;        ///< mean |difference| over pixels and channels
  double fractionOver = 0.0;   ///< pixels whose largest channel difference exceeds 32
  Image diff;
};

ImageDifference compareImages(const Image& a, const Image& b) {
  ImageDifference d;
  d.diff = Image(a.width, a.height);
  std::size_t over = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    float largest = 0.0f;
    for (int c = 0; c < 3; ++c) {
      // PNG readback is linear; compare in display units, as a person would see it.
      auto display = [](float v) { return 255.0f * (v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1 / 2.4f) - 0.055f); };
      const float delta = std::abs(display(a.pixels[i][c]) - display(b.pixels[i][c]));
      d.meanAbs += delta;
      largest = std::max(largest, delta);
    }
    if (largest > 32.0f) ++over;
    d.diff.pixels[i] = glm::vec3(largest / 255.0f);
  }
  d.meanAbs /= double(a.pixels.size()) * 3.0;
  d.fractionOver = double(over) / double(a.pixels.size());
  return d;
}

TEST(EditorGui, PaintSurfaceAndSliceThenSaveMatchesGoldenScreenshot) {
  // A surface stroke across the 3D view's centre and a slice stroke in the z slice view,
  // then Ctrl+S: the scene gains cube_material.vdb, painted only near both strokes, every
  // painted σt between the base and the brush's set target (set mode moves towards it).
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  // c: from the colour brush to sigma_t, the brush this picture was made with. The slice
  // stroke runs along the z slice view's centre row (y 102).
  test::writeText(p.events,
                  EventScript().key("c", 'c').drag(200, 402, 280, 402, 8).drag(760, 102, 840, 102, 8).ctrl('s').str());
  const fs::path shot = p.dir / "actual.png";
  const RunResult r =
      runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--screenshot", shot.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  ASSERT_TRUE(fs::exists(p.saved)) << "Ctrl+S did not write " << p.saved << "; stderr: " << r.stderrText;
  EXPECT_EQ(loadScene(p.scene).material.vdb.value_or(""), p.saved) << "the scene should now name the saved set";

  auto set = loadMaterialSet(p.saved);
  ASSERT_GT(set->sigmaT->activeVoxelCount(), 0u);
  bool nearFront = false, nearCentrePlane = false;
  for (auto it = set->sigmaT->cbeginValueOn(); it; ++it) {
    const openvdb::Vec3d rest = set->sigmaT->transform().indexToWorld(it.getCoord());
    const openvdb::Vec3s v = *it;
    // Base σt.x 1.0, brush target 2 x base = 2.0: every painted value lies in between.
    EXPECT_GE(v.x(), 1.0f - 1e-5f);
    EXPECT_LE(v.x(), 2.0f + 1e-5f);
    if (rest.z() > 3.0) nearFront = true;
    if (std::abs(rest.z()) < 1.5) nearCentrePlane = true;
    // Radius 8 % of the cube's diagonal (~1.4 mm) plus the support: nothing far off.
    EXPECT_LT(std::abs(rest.y()), 3.0) << "voxel painted far from both strokes at y = " << rest.y();
  }
  EXPECT_TRUE(nearFront) << "the surface stroke should paint near the front face (z = 5)";
  EXPECT_TRUE(nearCentrePlane) << "the slice stroke should paint on the z = 0 slice";

  const fs::path golden = test::sourceDir() / "tests" / "golden" / "editor_paint.png";
  if (std::getenv("SSLPV_UPDATE_GOLDEN")) {
    fs::create_directories(golden.parent_path());
    fs::copy_file(shot, golden, fs::copy_options::overwrite_existing);
    GTEST_SKIP() << "golden image updated from this run: " << golden;
  }
  ASSERT_TRUE(fs::exists(golden)) << golden << " is missing (SSLPV_UPDATE_GOLDEN=1 writes it)";
  const Image actual = readImage(shot), expected = readImage(golden);
  ASSERT_EQ(actual.width, expected.width);
  ASSERT_EQ(actual.height, expected.height);
  const ImageDifference d = compareImages(actual, expected);
  // Text with timings changes between runs; the picture itself must not.
  if (d.meanAbs > 1.5 || d.fractionOver > 0.005) {
    const fs::path keep = fs::temp_directory_path() / "sslpv-editor-gui";
    fs::create_directories(keep);
    fs::copy_file(shot, keep / "actual.png", fs::copy_options::overwrite_existing);
    writeImage(d.diff, keep / "diff.png");
    ADD_FAILURE() << "screenshot differs from " << golden << ": mean |diff| " << d.meanAbs << " / 255, "
                  << d.fractionOver * 100 << " % of pixels off by more than 32; actual and diff in " << keep;
  }
}

TEST(EditorGui, UndoThenSaveRestoresTheBase) {
  // Paint, Ctrl+Z, Ctrl+S: the saved set has no active voxel (everything is the base).
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  test::writeText(p.events, EventScript().drag(200, 402, 280, 402, 6).ctrl('z').ctrl('s').str());
  const RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  ASSERT_TRUE(fs::exists(p.saved)) << r.stderrText;
  EXPECT_EQ(activeVoxels(p.saved), 0u);
}

TEST(EditorGui, UnsavedWorkIsRecoveredAtTheNextStart) {
  // Session 1 paints and ends without saving: the recovery file keeps the work. Session 2
  // answers the recovery offer with R and saves: the saved set equals the recovered one,
  // and the recovery file is gone.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  test::writeText(p.events, EventScript().drag(200, 402, 280, 402, 6).str());
  RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--autosave-seconds", "0", "--play",
                           p.events.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  ASSERT_TRUE(fs::exists(p.recovery)) << "no recovery file after an unsaved session; stderr: " << r.stderrText;
  EXPECT_FALSE(fs::exists(p.saved));
  const std::size_t recovered = activeVoxels(p.recovery);
  ASSERT_GT(recovered, 0u);

  test::writeText(p.events, EventScript().key("R", 'R', 1).ctrl('s').str());
  r = runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  ASSERT_TRUE(fs::exists(p.saved)) << r.stderrText;
  EXPECT_EQ(activeVoxels(p.saved), recovered);
  EXPECT_FALSE(fs::exists(p.recovery)) << "a save should delete the recovery file";
}

TEST(EditorGui, UnreadableSceneIsReportedInTheWindowAndOnStderr) {
  // A scene with an unknown key: exit 2, one stderr line naming file and key, and the
  // error window (screenshot written) instead of a crash.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const fs::path scene = dir / "bad.json", shot = dir / "error.png";
  std::string text = kScene;
  text.replace(text.find("\"units\""), 7, "\"unitz\"");
  test::writeText(scene, text);
  const RunResult r = runEditor({scene.string(), "--screenshot", shot.string(), "--exit"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.stderrText.find("bad.json"), std::string::npos) << r.stderrText;
  EXPECT_NE(r.stderrText.find("unitz"), std::string::npos) << r.stderrText;
  EXPECT_TRUE(fs::exists(shot)) << "the error window was not shown";
}

TEST(EditorGui, QuitAsksBeforeDroppingUnsavedWork) {
  // One q with unsaved changes only warns (the recovery file keeps the work at exit); two
  // q quit without saving and remove the recovery file.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  test::writeText(p.events, EventScript().drag(200, 402, 280, 402, 4).key("q", 'q').str());
  RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--autosave-seconds", "0", "--play",
                           p.events.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  EXPECT_TRUE(fs::exists(p.recovery)) << "one q must not drop the unsaved work";
  fs::remove(p.recovery);

  test::writeText(p.events, EventScript().drag(200, 402, 280, 402, 4).key("q", 'q').key("q", 'q').str());
  r = runEditor({p.scene.string(), "--size", "960x600", "--autosave-seconds", "0", "--play", p.events.string(),
                 "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  EXPECT_FALSE(fs::exists(p.recovery)) << "quitting without saving should not leave a recovery file";
  EXPECT_FALSE(fs::exists(p.saved));
}

/// Every active voxel of the saved set shows `colour` behind `ior` within 1 % (adding-doubling
/// of α' from the stored floats) at scatter distance `distance` and phase g; returns how many.
std::size_t expectVoxelsShowColour(const fs::path& vdb, const glm::dvec3& colour, const glm::dvec3& distance, double g,
                                   double ior) {
  const auto set = loadMaterialSet(vdb);
  auto s = set->sigmaS->getConstAccessor();
  auto gs = set->g->getConstAccessor();
  std::size_t voxels = 0;
  for (auto it = set->sigmaT->cbeginValueOn(); it; ++it, ++voxels) {
    const openvdb::Vec3s sigmaT = *it, sigmaS = s.getValue(it.getCoord());
    const double vg = gs.getValue(it.getCoord());
    EXPECT_NEAR(vg, g, 1e-6) << it.getCoord();
    for (int c = 0; c < 3; ++c) {
      const double reducedT = sigmaT[c] - sigmaS[c] * vg;
      const double rd = addingDoublingHalfSpace(sigmaS[c] * (1.0 - vg) / reducedT, ior).rd;
      EXPECT_NEAR(rd, colour[c], 0.01 * colour[c]) << it.getCoord() << " channel " << c;
      EXPECT_NEAR(1.0 / reducedT, distance[c], 1e-4 * distance[c]) << it.getCoord() << " channel " << c;
      if (::testing::Test::HasFailure()) return voxels;
    }
  }
  return voxels;
}

/// Strength 1 (= ten times) and constant falloff (o: smooth -> gaussian -> constant), so
/// every voxel a dab reaches holds the brush's material exactly.
EventScript& fullStrength(EventScript& events) {
  for (int i = 0; i < 10; ++i) events.key("equal", '=');
  return events.key("o", 'o').key("o", 'o');
}

TEST(EditorGui, TypedColourPaintsVoxelsThatShowIt) {
  // Enter, then the surface colour, the scatter distance and g typed in; a stroke at full
  // strength; Ctrl+S. The painted voxels show the typed colour behind the scene's ior 1.3.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  std::string scene = kScene;
  scene.replace(scene.find("\"g\": 0.0}"), 9, "\"g\": 0.0}, \"ior\": 1.3");
  test::writeText(p.scene, scene);
  EventScript events;
  events.key("Return", 13).type("0.7,0.3,0.1").type("2").type("0.3");
  fullStrength(events).drag(200, 402, 280, 402, 8).ctrl('s');
  test::writeText(p.events, events.str());
  const RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  ASSERT_TRUE(fs::exists(p.saved)) << r.stderrText;
  EXPECT_GT(expectVoxelsShowColour(p.saved, {0.7, 0.3, 0.1}, glm::dvec3(2.0), 0.3, 1.3), 100u);
}

TEST(EditorGui, ClickedSwatchPaintsItsMaterial) {
  // A click on the third swatch (under the 3D view) picks that Jensen material; the stroke
  // paints its σt and σs (g = 0), index-matched scene.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  EventScript events;
  // Swatch i spans x from (0.003 + i / 24) * 960; the row's text sits just above y = 0.345 * 600.
  events.click(int((0.003 + 2.0 / 24.0) * 960.0) + 8, int(0.345 * 600.0) + 5);
  fullStrength(events).drag(200, 402, 280, 402, 8).ctrl('s');
  test::writeText(p.events, events.str());
  const RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  ASSERT_TRUE(fs::exists(p.saved)) << r.stderrText;
  const MeasuredMaterial& m = measuredMaterials()[2];
  const MaterialSample preset = *presetMaterial(m.name, 0.0f, 1.0);
  const auto set = loadMaterialSet(p.saved);
  auto s = set->sigmaS->getConstAccessor();
  std::size_t voxels = 0;
  for (auto it = set->sigmaT->cbeginValueOn(); it; ++it, ++voxels) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR((*it)[c], preset.sigmaT[c], 1e-4 * preset.sigmaT[c]) << m.name << " at " << it.getCoord();
      ASSERT_NEAR(s.getValue(it.getCoord())[c], preset.sigmaS[c], 1e-4 * preset.sigmaS[c]) << m.name;
    }
  }
  EXPECT_GT(voxels, 100u) << "the swatch click must not paint, the stroke must";
}

// Fraction of pixels in [x0, x1) x [y0, y1) (image rows from the top) whose largest
// channel differs by more than 32 of 255.
double changedFraction(const Image& a, const Image& b, int x0, int y0, int x1, int y1) {
  Image ca(x1 - x0, y1 - y0), cb(x1 - x0, y1 - y0);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      ca.at(x - x0, y - y0) = a.at(x, y);
      cb.at(x - x0, y - y0) = b.at(x, y);
    }
  return compareImages(ca, cb).fractionOver;
}

TEST(EditorGui, HelpOverlayAndPreviewFollowingTheCamera) {
  // h draws the key list over the window; zooming the 3D view (wheel) re-renders the
  // preview through the new camera, so the preview half of the window changes while
  // nothing was painted.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  const fs::path plain = p.dir / "plain.png", help = p.dir / "help.png", zoomed = p.dir / "zoomed.png";
  auto run = [&](const std::string& events, const fs::path& shot) {
    test::writeText(p.events, events);
    const RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--screenshot",
                                   shot.string(), "--exit"});
    ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  };
  run(EventScript().str(), plain);
  run(EventScript().key("h", 'h').str(), help);
  run(EventScript().wheelForward(240, 402, 5).str(), zoomed);
  const Image a = readImage(plain), b = readImage(help), c = readImage(zoomed);
  // The overlay's text block sits in the lower left of the window.
  EXPECT_GT(changedFraction(a, b, 0, 100, 960, 560), 0.05) << "the help overlay did not appear";
  // Preview: x 480..960, rows 20..396 (below its label line).
  EXPECT_GT(changedFraction(a, c, 480, 20, 960, 396), 0.02) << "the preview did not follow the camera";
  EXPECT_FALSE(fs::exists(p.recovery)) << "nothing was painted, so there is nothing to recover";
}

TEST(EditorGui, BKeyMakesThePreviewThe3dView) {
  // b: the 3D view shows the SSLPV preview as its background, so its top-left corner turns
  // from the view's own grey-blue to the preview's black; a second b brings the mesh back.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  auto cornerBlack = [&](const std::string& events) {
    const fs::path shot = p.dir / "shot.png";
    test::writeText(p.events, events);
    const RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--screenshot",
                                   shot.string(), "--exit"});
    EXPECT_EQ(r.exitCode, 0) << r.stderrText;
    const Image image = readImage(shot);
    std::size_t black = 0, n = 0;
    for (int y = 20; y < 60; ++y)
      for (int x = 20; x < 60; ++x, ++n) {
        const glm::vec3 c = image.at(x, y);
        if (c.x + c.y + c.z < 0.01f) ++black;
      }
    return double(black) / double(n);
  };
  EXPECT_GT(cornerBlack(EventScript().key("b", 'b').str()), 0.95) << "b did not put the preview in the 3D view";
  EXPECT_LT(cornerBlack(EventScript().key("b", 'b').key("b", 'b').str()), 0.05) << "a second b should bring the mesh view back";
}

std::vector<std::string> dirNames(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(EditorGui, ExportPromptStartsEmptySoTheTypedPathIsTheWholePath) {
  // The prompt was prefilled with cube_export.vdb and typing appended to it
  // ("cube_export.vdb/tmp/x.vdb"). Now it starts empty: the typed path is written as
  // typed; Enter on an empty prompt writes the suggestion.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  const fs::path typed = p.dir / "typed.vdb";
  test::writeText(p.events, EventScript()
                                .drag(200, 402, 280, 402, 4)
                                .ctrl('e')
                                .typePath(typed.string())
                                .enter()
                                .ctrl('e')
                                .enter()
                                .str());
  const RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  ASSERT_TRUE(fs::exists(typed)) << r.stderrText;
  EXPECT_GT(activeVoxels(typed), 0u);
  EXPECT_TRUE(fs::exists(p.dir / "cube_export.vdb")) << "Enter on the empty prompt writes the suggestion";
  std::vector<std::string> names = dirNames(p.dir.path());
  names.erase(std::remove(names.begin(), names.end(), p.recovery.filename().string()), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"cube.json", "cube_export.vdb", "events.txt", "typed.vdb"}))
      << "an export is not a save; nothing else is written";
}

TEST(EditorGui, CtrlSAsksBeforeReplacingAHandMadeSetAndSaveAsKeepsIt) {
  // The scene names a set sslpv's painting tools did not write: Ctrl+S writes nothing and
  // says why; Ctrl+Shift+S with a typed path writes there and the scene's material.vdb
  // (only that value) names the new file.
  if (const std::string why = editorSkipReason(); !why.empty()) GTEST_SKIP() << why;
  Project p;
  // Made by another tool, as the examples' sets are.
  MaterialSet hand = *makeEmptyMaterialSet(MaterialSample{{1.0f, 1.2f, 1.4f}, {0.9f, 1.0f, 1.1f}, 0.0f}, 0.1, "mm");
  hand.creator = "sslpv make_examples";
  saveMaterialSet(hand, p.dir / "hand.vdb");
  nlohmann::ordered_json scene = nlohmann::ordered_json::parse(kScene);
  scene["material"]["vdb"] = "hand.vdb";
  const std::string sceneText = scene.dump(2);
  test::writeText(p.scene, sceneText);
  const std::string handBytes = test::readText(p.dir / "hand.vdb");
  const fs::path mine = p.dir / "mine.vdb";
  test::writeText(p.events, EventScript()
                                .drag(200, 402, 280, 402, 4)
                                .ctrl('s')
                                .key("S", 19, 3)  // Ctrl+Shift+S
                                .typePath(mine.string())
                                .enter()
                                .str());
  const RunResult r = runEditor({p.scene.string(), "--size", "960x600", "--play", p.events.string(), "--exit"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  EXPECT_NE(r.stderrText.find("hand.vdb: not written by sslpv's painting tools"), std::string::npos) << r.stderrText;
  EXPECT_EQ(test::readText(p.dir / "hand.vdb"), handBytes) << "the hand-made set was replaced";
  ASSERT_TRUE(fs::exists(mine)) << r.stderrText;
  EXPECT_GT(activeVoxels(mine), 0u);
  const std::string after = test::readText(p.scene);
  const std::size_t at = sceneText.find("\"hand.vdb\"");
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(after, sceneText.substr(0, at) + "\"mine.vdb\"" + sceneText.substr(at + 10))
      << "only material.vdb may change";
  EXPECT_FALSE(fs::exists(p.recovery)) << "saved: no recovery file";
}

}  // namespace
}  // namespace sslpv
