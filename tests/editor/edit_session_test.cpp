// The editor's headless document (editor/edit_session.h): the unsaved flag follows the
// history position, save/export/autosave write atomically and a failed write changes
// nothing, crash recovery restores the painted voxels bit for bit, and the incremental
// preview equals a full render of the saved scene. Each test states what it checks.
#include "volume/eval/image_metrics.h"
#include "editor/edit_session.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstring>
#include <nlohmann/json.hpp>

#include "edit_session_support.h"
#include "material_compare.h"
#include "test_support.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/core/error.h"
#include "volume/material/material_set.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> listDir(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}


/// A set made by another tool, as the examples' (creator "sslpv make_examples").
void saveHandMade(MaterialSet set, const fs::path& file) {
  set.creator = "sslpv make_examples";
  saveMaterialSet(set, file);
}

/// A set as an earlier editor session saved it: painted output, replaced without asking.
void saveAsPaintedOutput(MaterialSet set, const fs::path& file) {
  set.creator = "sslpv edit";
  saveMaterialSet(set, file);
}

TEST(EditSession, UnsavedFollowsTheHistoryPosition) {
  // Saved = the revision on top of the undo stack at load/save; undoing back to it is
  // saved again, a new stroke after undo (which drops the redo branch) is not.
  Files f;
  EditSession s(f.scene, smallPreview());
  EXPECT_FALSE(s.unsaved()) << "a freshly loaded scene";
  EXPECT_EQ(s.changeCount(), 0u);

  ASSERT_GT(s.applyStroke(darkStroke()).voxelsChanged, 0u);
  EXPECT_TRUE(s.unsaved()) << "after stroke A";
  ASSERT_TRUE(s.undo());
  EXPECT_FALSE(s.unsaved()) << "undo back to the loaded state";
  ASSERT_TRUE(s.redo());
  EXPECT_TRUE(s.unsaved()) << "redo of A";
  EXPECT_EQ(s.changeCount(), 3u) << "stroke, undo, redo";

  s.save();
  EXPECT_FALSE(s.unsaved()) << "saved at A";
  ASSERT_TRUE(s.undo());
  EXPECT_TRUE(s.unsaved()) << "undo below the saved A";
  ASSERT_TRUE(s.redo());
  EXPECT_FALSE(s.unsaved()) << "redo back to the saved A";

  // Erasing where nothing was painted changes no voxel: nothing differs from the save.
  Stroke noop = darkStroke();
  noop.brush.channel = BrushChannel::All;
  noop.brush.mode = BrushMode::Erase;
  noop.points = {{-3.0, -3.0, -3.0}};
  EXPECT_EQ(s.applyStroke(noop).voxelsChanged, 0u);
  EXPECT_FALSE(s.unsaved()) << "a stroke that changed nothing";
  ASSERT_TRUE(s.undo());

  // Mid-stroke the voxels differ from the saved state already.
  s.beginStroke(darkStroke(-2.0).brush);
  EXPECT_FALSE(s.unsaved()) << "a stroke that has not painted yet";
  EXPECT_GT(s.addPoints({{-2.0, 0.0, 4.0}}).voxelsWritten, 0u);
  EXPECT_TRUE(s.unsaved()) << "mid-stroke, after dabs";
  EXPECT_THROW(s.save(), InputError) << "save during a stroke is refused";
  s.endStroke();
  EXPECT_TRUE(s.unsaved());

  // Saved at A; undo B and A, paint C: undoing C lands below A, not on it.
  ASSERT_TRUE(s.undo());
  ASSERT_TRUE(s.undo());
  EXPECT_TRUE(s.unsaved()) << "below the saved A";
  s.applyStroke(darkStroke(-2.0));
  EXPECT_FALSE(s.canRedo()) << "a new stroke drops the redo branch";
  EXPECT_TRUE(s.unsaved()) << "paint C after undoing A";
  ASSERT_TRUE(s.undo());
  EXPECT_TRUE(s.unsaved()) << "the state below A is not the saved A";
  EXPECT_FALSE(s.undo()) << "history holds only C now";
}

TEST(EditSession, SaveWithoutVdbWritesMaterialFileAndRewritesTheScene) {
  // The scene gains material.vdb = "scene_material.vdb" with every other key and the key
  // order kept; the file holds the painted voxels bit for bit, creator "sslpv edit".
  Files f;
  const std::string original = readText(f.scene);
  EditSession s(f.scene, smallPreview());
  EXPECT_TRUE(s.paths().saveUpdatesScene);
  EXPECT_EQ(s.paths().saveTarget, f.dir / "scene_material.vdb");
  EXPECT_EQ(s.paths().recovery, f.dir / "scene.json.recovery.vdb");
  ASSERT_GT(s.applyStroke(darkStroke()).voxelsChanged, 0u);
  s.save();
  EXPECT_FALSE(s.unsaved());
  EXPECT_FALSE(s.paths().saveUpdatesScene) << "the scene now references the file";
  EXPECT_EQ(listDir(f.dir.path()), (std::vector<std::string>{"scene.json", "scene_material.vdb"})) << "no temporary left";

  const Scene reloaded = loadScene(f.scene);
  ASSERT_TRUE(reloaded.material.vdb);
  EXPECT_EQ(*reloaded.material.vdb, f.dir / "scene_material.vdb");
  const ordered before = ordered::parse(original), after = ordered::parse(readText(f.scene));
  EXPECT_EQ(after["material"]["vdb"], "scene_material.vdb") << "relative to the scene's folder";
  ordered expected = before;
  expected["material"]["vdb"] = "scene_material.vdb";
  EXPECT_EQ(after.dump(), expected.dump()) << "keys, values and key order kept";

  const auto written = loadMaterialSet(f.dir / "scene_material.vdb");
  EXPECT_EQ(written->creator, "sslpv edit");
  EXPECT_TRUE(sameVoxels(*written, *s.engine().materialSet()));

  EditSession again(f.scene, smallPreview());
  EXPECT_FALSE(again.unsaved());
  EXPECT_FALSE(again.paths().saveUpdatesScene);
  EXPECT_TRUE(sameVoxels(*again.engine().materialSet(), *s.engine().materialSet()))
      << "a new session reads back what was painted";
}

TEST(EditSession, SaveWithVdbReplacesThatFileAndLeavesTheSceneAlone) {
  // The set is written over material.vdb (in its own transform, voxel 0.1), the scene
  // file is not touched, and nothing else appears in the folder.
  TempDir dir;
  fs::create_directory(dir / "mat");
  auto initial = makeEmptyMaterialSet(MaterialSample{{1.0f, 1.2f, 1.4f}, {0.9f, 1.0f, 1.1f}, 0.1f}, 0.1, "mm");
  saveAsPaintedOutput(*initial, dir / "mat" / "painted.vdb");
  ordered json = sceneJson();
  json["material"]["vdb"] = "mat/painted.vdb";
  writeText(dir / "scene.json", json.dump(2));
  const std::string sceneText = readText(dir / "scene.json");

  EditSession s(dir / "scene.json", smallPreview());
  EXPECT_FALSE(s.paths().saveUpdatesScene);
  EXPECT_EQ(s.paths().saveTarget, dir / "mat" / "painted.vdb");
  ASSERT_GT(s.applyStroke(darkStroke()).voxelsChanged, 0u);
  s.save();
  EXPECT_FALSE(s.unsaved());
  EXPECT_EQ(readText(dir / "scene.json"), sceneText);
  EXPECT_EQ(listDir(dir / "mat"), std::vector<std::string>{"painted.vdb"});
  const auto written = loadMaterialSet(dir / "mat" / "painted.vdb");
  EXPECT_TRUE(sameVoxels(*written, *s.engine().materialSet()));
  EXPECT_NEAR(written->sigmaT->voxelSize()[0], 0.1, 1e-12) << "the file's own voxel size is kept";
  EXPECT_GT(written->sigmaT->activeVoxelCount(), 0u);
}

/// The common checks of a save that could not write: exception naming `named`, the old
/// files byte-identical, the session still unsaved with its history.
void expectFailedSaveChangesNothing(EditSession& s, const fs::path& named, const std::vector<fs::path>& files) {
  std::vector<std::string> before;
  for (const fs::path& file : files) before.push_back(readText(file));
  const bool couldUndo = s.canUndo();
  const auto voxels = deepCopy(*s.engine().materialSet());
  try {
    s.save();
    ADD_FAILURE() << "save() succeeded although " << named << " could not be written";
  } catch (const std::runtime_error& e) {
    // InputError (a read-only folder) or ResourceError (a write that failed: "FILE: write
    // failed: File too large"); either names the file.
    EXPECT_TRUE(dynamic_cast<const InputError*>(&e) || dynamic_cast<const ResourceError*>(&e)) << e.what();
    EXPECT_NE(std::string(e.what()).find(named.string()), std::string::npos) << e.what();
  }
  for (std::size_t i = 0; i < files.size(); ++i)
    EXPECT_TRUE(readText(files[i]) == before[i]) << files[i] << " changed";
  EXPECT_TRUE(s.unsaved());
  EXPECT_EQ(s.canUndo(), couldUndo);
  EXPECT_TRUE(sameVoxels(*s.engine().materialSet(), *voxels));
}

TEST(EditSession, SaveIntoReadOnlyDirectoryFailsAndChangesNothing) {
  // chmod 0555 on the material's folder: save must fail naming the file, keep the old
  // file byte-identical and stay unsaved; after chmod 0755 it succeeds.
  TempDir dir;
  fs::create_directory(dir / "mat");
  ordered json = sceneJson();
  json["material"]["vdb"] = "mat/painted.vdb";
  saveAsPaintedOutput(*makeEmptyMaterialSet(MaterialSample{}, 0.1, "mm"), dir / "mat" / "painted.vdb");
  writeText(dir / "scene.json", json.dump(2));
  EditSession s(dir / "scene.json", smallPreview());
  s.applyStroke(darkStroke());
  s.save();
  s.applyStroke(darkStroke(-2.0));

  ASSERT_EQ(::chmod((dir / "mat").c_str(), 0555), 0);
  if (::access((dir / "mat").c_str(), W_OK) == 0) {
    ::chmod((dir / "mat").c_str(), 0755);
    GTEST_SKIP() << "SKIPPED: running as root (uid " << ::geteuid()
                 << "), chmod 0555 does not block writes; SaveFailsWhenTheFileCannotBeWritten covers this";
  }
  expectFailedSaveChangesNothing(s, dir / "mat" / "painted.vdb", {dir / "mat" / "painted.vdb", dir / "scene.json"});
  ASSERT_EQ(::chmod((dir / "mat").c_str(), 0755), 0);
  s.save();
  EXPECT_FALSE(s.unsaved());
}

/// Limits the size of files this process writes (EFBIG, which root cannot bypass as it
/// can chmod), restoring the limit on destruction. SIGXFSZ would kill the process.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    previous_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, previous_);
  }
  bool ok() const { return ok_; }

 private:
  rlimit saved_{};
  void (*previous_)(int) = SIG_DFL;
  bool ok_ = false;
};

TEST(EditSession, SaveFailsWhenTheFileCannotBeWritten) {
  // A file-size limit far below the set's size makes the VDB write fail (for root too):
  // with material.vdb the old file stays byte-identical; without it neither the scene
  // nor a scene_material.vdb appears changed. The session stays unsaved in both cases.
  TempDir dir;
  ordered json = sceneJson();
  json["material"]["vdb"] = "painted.vdb";
  saveAsPaintedOutput(*makeEmptyMaterialSet(MaterialSample{}, 0.1, "mm"), dir / "painted.vdb");
  writeText(dir / "with.json", json.dump(2));
  writeText(dir / "without.json", sceneJson().dump(2));

  EditSession with(dir / "with.json", smallPreview());
  with.applyStroke(darkStroke());
  EditSession without(dir / "without.json", smallPreview());
  without.applyStroke(darkStroke());
  {
    // The painted set is ~100 kB; the empty file and the scenes are below 4 kB.
    ASSERT_GT(fs::file_size(dir / "painted.vdb"), 0u);
    FileSizeLimit limit(4096);
    ASSERT_TRUE(limit.ok());
    expectFailedSaveChangesNothing(with, dir / "painted.vdb", {dir / "painted.vdb", dir / "with.json"});
    expectFailedSaveChangesNothing(without, dir / "without_material.vdb", {dir / "without.json"});
  }
  EXPECT_FALSE(fs::exists(dir / "without_material.vdb"));
  EXPECT_TRUE(without.paths().saveUpdatesScene);
  EXPECT_EQ(listDir(dir.path()), (std::vector<std::string>{"painted.vdb", "with.json", "without.json"}))
      << "no temporary file left";
  with.save();
  without.save();
  EXPECT_FALSE(with.unsaved());
  EXPECT_FALSE(without.unsaved());
  EXPECT_TRUE(sameVoxels(*loadMaterialSet(dir / "painted.vdb"), *with.engine().materialSet()));
}

// A hand-formatted scene naming a hand-made set.
const std::string kHandScene =
    "{\n"
    "  \"units\": \"mm\",\n"
    "  \"mesh\": {\"primitive\": \"box\", \"min\": [-5, -5, -5], \"max\": [5, 5, 5]},\n"
    "  \"camera\": {\"position\": [6, 8, 30], \"target\": [0, 0, 0], \"fov_y_deg\": 35,\n"
    "             \"width\": 64, \"height\": 48},\n"
    "  \"material\": {\"base\": {\"sigma_t\": [1.0, 1.2, 1.4], \"sigma_s\": [0.9, 1.0, 1.1], \"g\": 0.1},\n"
    "               \"vdb\": \"hand.vdb\", \"ior\": 1.3},\n"
    "  \"lights\": [{\"type\": \"point\", \"position\": [10, 15, 30], \"intensity\": 2000}],\n"
    "  \"lpv\": {\"resolution\": 16, \"steps\": 8, \"shadow_map\": 128}\n"
    "}\n";

std::string replacedOnce(const std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.substr(0, at) + to + text.substr(at + from.size());
}

TEST(EditSession, SaveOverAHandMadeSetNeedsConfirmationAndWritesNothingUntilThen) {
  // Ctrl+S on an example replaced its hand-made set in place: now save() refuses with
  // SaveNeedsConfirmation (both files byte-identical, still unsaved) until confirmed.
  TempDir dir;
  saveHandMade(*makeEmptyMaterialSet(MaterialSample{}, 0.1, "mm"), dir / "hand.vdb");
  writeText(dir / "scene.json", kHandScene);
  const std::string handBytes = readText(dir / "hand.vdb");
  EditSession s(dir / "scene.json", smallPreview());
  EXPECT_TRUE(s.paths().saveNeedsConfirmation);
  ASSERT_GT(s.applyStroke(darkStroke()).voxelsChanged, 0u);
  EXPECT_THROW(s.save(), SaveNeedsConfirmation);
  EXPECT_EQ(readText(dir / "hand.vdb"), handBytes);
  EXPECT_EQ(readText(dir / "scene.json"), kHandScene);
  EXPECT_TRUE(s.unsaved());
  s.save(/*replaceConfirmed=*/true);
  EXPECT_FALSE(s.unsaved());
  EXPECT_TRUE(sameVoxels(*loadMaterialSet(dir / "hand.vdb"), *s.engine().materialSet()));
  EXPECT_FALSE(s.paths().saveNeedsConfirmation) << "the file now holds this session's work";
  EXPECT_EQ(readText(dir / "scene.json"), kHandScene);
}

TEST(EditSession, SaveAsWritesTheNamedSetAndChangesOnlyMaterialVdbInTheScene) {
  TempDir dir;
  saveHandMade(*makeEmptyMaterialSet(MaterialSample{}, 0.1, "mm"), dir / "hand.vdb");
  writeText(dir / "scene.json", kHandScene);
  const std::string handBytes = readText(dir / "hand.vdb");
  EditSession s(dir / "scene.json", smallPreview());
  ASSERT_GT(s.applyStroke(darkStroke()).voxelsChanged, 0u);
  EXPECT_THROW(s.saveAs(dir / "mine.png"), InputError);
  s.saveAs(dir / "mine.vdb");
  EXPECT_FALSE(s.unsaved());
  EXPECT_EQ(readText(dir / "hand.vdb"), handBytes) << "the hand-made set is untouched";
  EXPECT_EQ(readText(dir / "scene.json"), replacedOnce(kHandScene, "\"hand.vdb\"", "\"mine.vdb\""))
      << "every other byte of the scene kept";
  EXPECT_TRUE(sameVoxels(*loadMaterialSet(dir / "mine.vdb"), *s.engine().materialSet()));
  EXPECT_EQ(s.paths().saveTarget, dir / "mine.vdb");
  // Later saves go to the new file without asking; Save As onto an existing file asks.
  s.applyStroke(darkStroke(1.0));
  s.save();
  EXPECT_FALSE(s.unsaved());
  EXPECT_THROW(s.saveAs(dir / "hand.vdb"), SaveNeedsConfirmation);
  EXPECT_EQ(readText(dir / "hand.vdb"), handBytes);
}

TEST(EditSession, SaveRecordsAMovedCameraInPlaceOfTheOldValues) {
  // The camera was not saved; now a save writes the preview's view (not its size) into
  // camera.position/target/fov_y_deg (and up where it changed), every other byte kept.
  TempDir dir;
  saveAsPaintedOutput(*makeEmptyMaterialSet(MaterialSample{}, 0.1, "mm"), dir / "hand.vdb");
  writeText(dir / "scene.json", kHandScene);
  EditSession s(dir / "scene.json", smallPreview());
  EXPECT_FALSE(s.cameraUnsaved());
  Camera moved = s.previewCamera();
  moved.position = glm::dvec3(-12.5, 4, 20);
  moved.target = glm::dvec3(0, 1, 0);
  moved.fovYDeg = 28;
  s.setPreviewCamera(moved);
  EXPECT_TRUE(s.cameraUnsaved());
  s.save();
  std::string expected = replacedOnce(kHandScene, "[6, 8, 30]", "[-12.5, 4, 20]");
  expected = replacedOnce(expected, "\"target\": [0, 0, 0]", "\"target\": [0, 1, 0]");
  expected = replacedOnce(expected, "\"fov_y_deg\": 35", "\"fov_y_deg\": 28");
  EXPECT_EQ(readText(dir / "scene.json"), expected);
  EXPECT_FALSE(s.cameraUnsaved());
  const Scene reloaded = loadScene(dir / "scene.json");
  EXPECT_EQ(reloaded.camera.width, 64) << "the scene's image size is not the preview's";
}

TEST(EditSession, ExportNeedsVdbExtensionAndKeepsTheSavedState) {
  // A non-.vdb name or a missing folder is an InputError that writes nothing; a .vdb
  // export holds the painted voxels and does not count as a save.
  Files f;
  EditSession s(f.scene, smallPreview());
  s.applyStroke(darkStroke());
  EXPECT_THROW(s.exportMaterialSet(f.dir / "out.png"), InputError);
  EXPECT_THROW(s.exportMaterialSet(f.dir / "out"), InputError);
  EXPECT_THROW(s.exportMaterialSet(f.dir / "missing" / "out.vdb"), InputError);
  EXPECT_EQ(listDir(f.dir.path()), std::vector<std::string>{"scene.json"});
  s.exportMaterialSet(f.dir / "out.VDB");
  EXPECT_TRUE(sameVoxels(*loadMaterialSet(f.dir / "out.VDB"), *s.engine().materialSet()));
  EXPECT_TRUE(s.unsaved()) << "an export is not a save";
  EXPECT_TRUE(s.paths().saveUpdatesScene);
}

TEST(EditSession, AutosaveThenRecoverReproducesThePaintedVoxels) {
  // autosave() writes <scene>.recovery.vdb; a new session (after a "crash") finds it,
  // recover() restores the voxels bit for bit with an empty history and counts as
  // unsaved; save() deletes the recovery file.
  Files f;
  EXPECT_FALSE(findRecoveryFile(f.scene));
  EditSession painted(f.scene, smallPreview());
  painted.applyStroke(darkStroke());
  painted.applyStroke(darkStroke(-2.0));
  EXPECT_TRUE(painted.autosaveStale());
  painted.autosave();
  EXPECT_FALSE(painted.autosaveStale()) << "autosave wrote the current state";
  ASSERT_EQ(findRecoveryFile(f.scene), std::optional<fs::path>(f.dir / "scene.json.recovery.vdb"));
  painted.applyStroke(darkStroke(2.0));
  EXPECT_TRUE(painted.autosaveStale()) << "a change after the autosave";
  painted.undo();
  // The recovery file holds the state after two strokes, which is the state now too.

  EditSession s(f.scene, smallPreview());
  EXPECT_FALSE(s.unsaved());
  s.renderPreview();
  EXPECT_FALSE(s.previewStale());
  s.recover();
  EXPECT_TRUE(s.unsaved()) << "a recovered state is unsaved even without history";
  EXPECT_FALSE(s.canUndo());
  EXPECT_FALSE(s.autosaveStale()) << "the recovery file holds exactly this state";
  EXPECT_TRUE(s.previewStale());
  EXPECT_TRUE(sameVoxels(*s.engine().materialSet(), *painted.engine().materialSet()));
  s.applyStroke(darkStroke(2.0));
  s.undo();
  EXPECT_TRUE(s.unsaved()) << "undoing back to the recovered state is still unsaved";

  s.save();
  EXPECT_FALSE(s.unsaved());
  EXPECT_FALSE(findRecoveryFile(f.scene)) << "save deletes the recovery file";
  EXPECT_TRUE(sameVoxels(*loadMaterialSet(s.paths().saveTarget), *painted.engine().materialSet()));

  painted.autosave();
  ASSERT_TRUE(findRecoveryFile(f.scene));
  painted.discardRecovery();
  EXPECT_FALSE(findRecoveryFile(f.scene)) << "discardRecovery deletes it";
  EXPECT_NO_THROW(painted.discardRecovery()) << "deleting a missing recovery file is not an error";
}

TEST(EditSession, UnusableRecoveryFileIsAnInputErrorAndChangesNothing) {
  // Garbage bytes, and a set whose grids do not share a transform (valid VDB, but the
  // brush engine cannot paint it): InputError naming the file, session untouched.
  Files f;
  EditSession s(f.scene, smallPreview());
  s.applyStroke(darkStroke());
  const auto voxels = deepCopy(*s.engine().materialSet());
  const fs::path recovery = f.dir / "scene.json.recovery.vdb";

  auto expectUnchanged = [&](const char* what) {
    try {
      s.recover();
      ADD_FAILURE() << what << ": recover() accepted it";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(recovery.string()), std::string::npos) << what << ": " << e.what();
    }
    EXPECT_TRUE(s.unsaved()) << what;
    EXPECT_TRUE(s.canUndo()) << what << ": history kept";
    EXPECT_TRUE(sameVoxels(*s.engine().materialSet(), *voxels)) << what;
  };
  writeText(recovery, "not a vdb file, the previous session crashed while writing it?");
  expectUnchanged("garbage");

  auto mismatched = deepCopy(*voxels);
  mismatched->sigmaS->setTransform(openvdb::math::Transform::createLinearTransform(0.37));
  saveMaterialSet(*mismatched, recovery);
  ASSERT_NO_THROW(loadMaterialSet(recovery)) << "the file itself must be valid for this case";
  expectUnchanged("differing transforms");
  s.save();
  EXPECT_FALSE(s.unsaved());
}

TEST(EditSession, IncrementalPreviewEqualsAFullRenderOfTheSavedScene) {
  // The preview resamples only the touched cells (mid-stroke, after the stroke, after an
  // undo, after two strokes in different places), and each frame equals a fresh CPU render of the same voxels within 1e-5
  // relative per pixel and channel (the region path computes the same field).
  Files f;
  EditSession s(f.scene, smallPreview());
  RenderReport report;
  const Image clean = s.renderPreview(&report);
  const std::size_t cells = report.frame.cellCount();
  EXPECT_EQ(report.resampledCells, cells) << "the first frame resamples everything";
  EXPECT_FALSE(s.previewStale());
  EXPECT_LT(maxRelativeDifference(clean, freshRender(f.scene, s)), 1e-5);

  // Mid-stroke: the dabs alone make the preview stale.
  const Stroke stroke = darkStroke();
  s.beginStroke(stroke.brush);
  ASSERT_GT(s.addPoints({stroke.points[0]}).voxelsWritten, 0u);
  EXPECT_TRUE(s.previewStale());
  const Image mid = s.renderPreview(&report);
  EXPECT_GT(report.resampledCells, 0u);
  EXPECT_LT(report.resampledCells, cells / 4) << "only the dab's region";
  s.exportMaterialSet(f.dir / "mid.vdb");
  ordered midScene = sceneJson();
  midScene["material"]["vdb"] = "mid.vdb";
  writeText(f.dir / "mid.json", midScene.dump());
  const double midDiff = maxRelativeDifference(mid, freshRender(f.dir / "mid.json", s));
  EXPECT_LT(midDiff, 1e-5);

  s.addPoints({stroke.points[1]});
  s.endStroke();
  EXPECT_TRUE(s.previewStale());
  const Image painted = s.renderPreview(&report);
  EXPECT_GT(report.resampledCells, 0u);
  EXPECT_LT(report.resampledCells, cells / 2);
  EXPECT_GT(maxRelativeDifference(painted, clean), 0.05) << "the stroke must visibly darken the preview";
  s.save();
  const double paintedDiff = maxRelativeDifference(painted, freshRender(f.scene, s));
  EXPECT_LT(paintedDiff, 1e-5);

  s.undo();
  EXPECT_TRUE(s.previewStale());
  const Image undone = s.renderPreview(&report);
  EXPECT_LT(report.resampledCells, cells / 2);
  EXPECT_LT(maxRelativeDifference(undone, clean), 1e-5) << "undo restores the clean frame";
  std::printf("[          ] cells %zu, last resampled %zu; max relative difference mid-stroke %.3g, after stroke %.3g\n",
              cells, report.resampledCells, midDiff, paintedDiff);

  // Two strokes apart before one frame: the frame resamples the union of both regions.
  s.applyStroke(darkStroke(-3.5));
  s.applyStroke(darkStroke(2.0));
  const Image two = s.renderPreview(&report);
  s.exportMaterialSet(f.dir / "two.vdb");
  midScene["material"]["vdb"] = "two.vdb";
  writeText(f.dir / "two.json", midScene.dump());
  EXPECT_LT(maxRelativeDifference(two, freshRender(f.dir / "two.json", s)), 1e-5);
  s.undo();
  s.undo();
  s.renderPreview();

  // A camera change re-shades only and matches a fresh render from there.
  Camera side = s.previewCamera();
  side.position = glm::dvec3(-25.0, 5.0, 15.0);
  s.setPreviewCamera(side);
  EXPECT_TRUE(s.previewStale());
  const Image moved = s.renderPreview(&report);
  EXPECT_TRUE(report.times.cached(Stage::Propagation)) << "a camera move does not re-propagate";
  // Undone to the clean state: the scene without any vdb renders it.
  writeText(f.dir / "clean.json", sceneJson().dump());
  EXPECT_LT(maxRelativeDifference(moved, freshRender(f.dir / "clean.json", s)), 1e-5);
}

TEST(EditSession, PreviewCameraKeepsTheSceneAspect) {
  // Longest side = PreviewOptions::longestSide, the other side scaled (rounded, at least
  // 16 px); setPreviewCamera's own width/height are replaced.
  struct Case {
    int width, height, longest, expectW, expectH;
  };
  for (const Case& c : {Case{64, 48, 256, 256, 192}, Case{300, 1000, 100, 30, 100}, Case{2000, 10, 256, 256, 16},
                        Case{512, 512, 200, 200, 200}}) {
    ordered json = sceneJson();
    json["camera"]["width"] = c.width;
    json["camera"]["height"] = c.height;
    Files f(json);
    PreviewOptions options;
    options.longestSide = c.longest;
    EditSession s(f.scene, options);
    EXPECT_EQ(s.previewCamera().width, c.expectW) << c.width << "x" << c.height << " -> " << c.longest;
    EXPECT_EQ(s.previewCamera().height, c.expectH) << c.width << "x" << c.height << " -> " << c.longest;
    EXPECT_EQ(s.previewCamera().position, s.scene().camera.position);
    Camera other = s.scene().camera;
    other.width = 7;
    other.height = 900;
    s.setPreviewCamera(other);
    EXPECT_EQ(s.previewCamera().width, c.expectW);
    EXPECT_EQ(s.previewCamera().height, c.expectH);
  }
  Files f;
  PreviewOptions tiny;
  tiny.longestSide = 8;
  EXPECT_THROW(EditSession(f.scene, tiny), InputError);
  EditSession s(f.scene, smallPreview());
  Camera bad = s.previewCamera();
  bad.target = bad.position;
  EXPECT_THROW(s.setPreviewCamera(bad), InputError);
}

}  // namespace
}  // namespace sslpv::test
