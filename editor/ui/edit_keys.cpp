// The editor window's keyboard and file operations: brush controls, undo/redo, files, help,
// quitting, the typed paths of "export material set" and "save as" (the keys' way), and
// the same operations as the Qt menus call them. Kept apart from the layout and painting.
#include <vtkActor.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>

#include <cctype>
#include <string>

#include "editor/ui/edit_window.h"

namespace sslpv {

EditWindow::FileOutcome EditWindow::saveFile(bool replaceConfirmed, std::string* why) {
  FileOutcome outcome = FileOutcome::Done;
  try {
    session_.save(replaceConfirmed);
    showMessage("saved " + session_.paths().saveTarget.filename().string(), false);
  } catch (const SaveNeedsConfirmation& e) {
    if (why) *why = e.what();
    outcome = FileOutcome::NeedsConfirmation;
  } catch (const std::exception& e) {
    // The session kept its state and the previous file: say so, keep working.
    if (why) *why = e.what();
    showMessage(std::string("save failed, nothing lost (changes still in memory): ") + e.what(), true);
    outcome = FileOutcome::Failed;
  }
  updateStatus();
  return outcome;
}

EditWindow::FileOutcome EditWindow::saveFileAs(const std::string& path, bool replaceConfirmed, std::string* why) {
  FileOutcome outcome = FileOutcome::Done;
  try {
    session_.saveAs(path, replaceConfirmed);
    showMessage("saved as " + path + " (the scene now uses it)", false);
  } catch (const SaveNeedsConfirmation& e) {
    if (why) *why = e.what();
    outcome = FileOutcome::NeedsConfirmation;
  } catch (const std::exception& e) {
    if (why) *why = e.what();
    showMessage(std::string("save as failed: ") + e.what(), true);
    outcome = FileOutcome::Failed;
  }
  updateStatus();
  return outcome;
}

EditWindow::FileOutcome EditWindow::exportFile(const std::string& path, std::string* why) {
  try {
    session_.exportMaterialSet(path);
    showMessage("exported material set to " + path, false);
    return FileOutcome::Done;
  } catch (const std::exception& e) {
    if (why) *why = e.what();
    showMessage(std::string("export failed: ") + e.what(), true);
    return FileOutcome::Failed;
  }
}

void EditWindow::undo() { afterChange(session_.undo(), "undo"); }
void EditWindow::redo() { afterChange(session_.redo(), "redo"); }

void EditWindow::quitWithoutSaving() {
  quit_ = true;
  quitArmed_ = true;
}

void EditWindow::startPrompt(PromptKind kind) {
  const std::filesystem::path& scene = session_.paths().scene;
  promptKind_ = kind;
  // Empty, not prefilled: typing must not append to a suggested path.
  prompt_ = std::string();
  replaceArmed_.clear();
  promptSuggestion_ =
      (scene.parent_path() / (scene.stem().string() + (kind == PromptKind::Export ? "_export.vdb" : "_painted.vdb")))
          .string();
  showPrompt();
}

void EditWindow::showPrompt() {
  const char* what = promptKind_ == PromptKind::Export ? "export material set to" : "save as";
  showMessage(std::string(what) + ": " + *prompt_ + "_\n(Enter: " + (prompt_->empty() ? promptSuggestion_ : *prompt_) +
                  ", Esc cancels)",
              false);
}

bool EditWindow::handlePromptKey(const std::string& keySym, char keyCode) {
  if (keySym == "Escape") {
    prompt_.reset();
    showMessage(promptKind_ == PromptKind::Export ? "export cancelled" : "save as cancelled", false);
    return true;
  }
  if (keySym != "Return" && keySym != "KP_Enter") {
    if (keySym == "BackSpace") {
      if (!prompt_->empty()) prompt_->pop_back();
    } else if (keyCode >= 32 && keyCode < 127) {
      prompt_->push_back(keyCode);
    }
    replaceArmed_.clear();
    showPrompt();
    return true;
  }
  const std::string path = prompt_->empty() ? promptSuggestion_ : *prompt_;
  try {
    if (promptKind_ == PromptKind::Export) {
      session_.exportMaterialSet(path);
      showMessage("exported material set to " + path, false);
    } else {
      // A second Enter on the same path is the user's answer to "replace it?".
      session_.saveAs(path, replaceArmed_ == path);
      showMessage("saved as " + path + " (the scene now uses it)", false);
    }
    prompt_.reset();
  } catch (const SaveNeedsConfirmation& e) {
    replaceArmed_ = path;
    showMessage(std::string(e.what()) + "\nEnter again replaces it, Esc cancels", true);
  } catch (const std::exception& e) {
    prompt_.reset();
    showMessage(std::string(promptKind_ == PromptKind::Export ? "export failed: " : "save as failed: ") + e.what(),
                true);
  }
  updateStatus();
  return true;
}

bool EditWindow::handleKey(const std::string& key, bool ctrl, bool shift, char keyCode) {
  if (prompt_) {
    handlePromptKey(key, keyCode);
    window_->Render();
    return true;
  }
  if (colourEntryField_) {
    handleColourEntryKey(key, keyCode);
    updateStatus();
    window_->Render();
    return true;
  }
  if (key != "q" && key != "e") quitArmed_ = false;
  const bool saveWasArmed = saveArmed_;
  saveArmed_ = false;
  const std::string lower = key.size() == 1 ? std::string(1, char(std::tolower(key[0]))) : key;
  bool handled = true;
  if (ctrl) {
    if (lower == "z" && !shift) {
      undo();
    } else if ((lower == "z" && shift) || lower == "y") {
      redo();
    } else if (lower == "s" && shift) {
      startPrompt(PromptKind::SaveAs);
    } else if (lower == "s") {
      save(saveWasArmed);
    } else if (lower == "e") {
      startPrompt(PromptKind::Export);
    } else {
      handled = false;
    }
  } else if (recoveryPending_ && key == "R") {
    try {
      session_.recover();
      recoveryPending_ = false;
      showMessage("recovered the earlier session's work (not saved yet: Ctrl+S saves it)", false);
      afterChange(std::nullopt, "recover");
    } catch (const std::exception& e) {
      showMessage(std::string("recovery failed: ") + e.what(), true);
    }
  } else if (recoveryPending_ && key == "D") {
    try {
      session_.discardRecovery();
      recoveryPending_ = false;
      showMessage("discarded the earlier session's unsaved work", false);
    } catch (const std::exception& e) {
      showMessage(std::string("could not delete the recovery file: ") + e.what(), true);
    }
  } else if (key == "space") {
    controls_.setPaintMode(!controls_.paintMode());
  } else if (lower == "c") {
    controls_.cycleChannel(shift ? -1 : 1);
    updateSlices();
  } else if (lower == "m") {
    controls_.cycleMode(shift ? -1 : 1);
  } else if (key == "o") {
    controls_.cycleFalloff();
  } else if (key == "comma" || key == "period") {
    controls_.adjustValue(key == "period" ? 1 : -1);
  } else if (key == "semicolon" || key == "apostrophe") {
    controls_.adjustAlbedo(key == "apostrophe" ? 1 : -1);
  } else if (key == "g" || key == "G") {
    if (controls_.brush().channel != BrushChannel::Colour) showMessage("g / G change the colour brush's g (c: channel)", false);
    controls_.adjustArtistG(key == "g" ? 1 : -1);
  } else if (key == "p" || key == "P") {
    controls_.cycleSwatch(key == "p" ? 1 : -1);
    updateSlices();
  } else if (key == "Return" || key == "KP_Enter") {
    startColourEntry();
  } else if (key == "v") {
    controls_.cycleComponent();
  } else if (key == "n") {
    controls_.negateValue();
  } else if (key == "bracketleft" || key == "bracketright") {
    controls_.scaleRadius(key == "bracketright" ? 1.2 : 1.0 / 1.2);
  } else if (key == "minus" || key == "equal" || key == "plus") {
    controls_.adjustStrength(key == "minus" ? -0.05 : 0.05);
  } else if (key == "x") {
    controls_.cycleMirror();
  } else if (lower == "i") {
    controls_.adjustDepth(shift ? -1 : 1);
  } else if (key == "b") {
    setPreviewAsMainView(!previewMain_);
  } else if (key == "l") {
    if (sliceRangeLocked()) {
      unlockSliceRange();
    } else if (const auto range = sliceRange()) {
      lockSliceRange(range->first, range->second);
    }
  } else if (key == "h" || key == "question" || key == "F1") {
    helpVisible_ = !helpVisible_;
    help_->SetVisibility(helpVisible_);
  } else if (key == "Escape") {
    helpVisible_ = false;
    help_->SetVisibility(false);
    showMessage("", false);
  } else if (key == "q" || key == "e") {
    if (session_.unsaved() && !quitArmed_) {
      quitArmed_ = true;
      showMessage("Unsaved changes: Ctrl+S saves them; press " + key + " again to quit without saving", true);
    } else {
      quit_ = true;
    }
  } else {
    handled = false;
  }
  if (handled) {
    const double radius = controls_.brush().radius;
    for (vtkActor* cursor : {cursor3d_.Get(), cursorSlice_[0].Get(), cursorSlice_[1].Get(), cursorSlice_[2].Get()})
      cursor->SetScale(radius);
    if (!controls_.paintMode())
      for (vtkActor* cursor : {cursor3d_.Get(), cursorSlice_[0].Get(), cursorSlice_[1].Get(), cursorSlice_[2].Get()})
        cursor->SetVisibility(false);
    updateStatus();
    window_->Render();
  }
  return handled;
}

}  // namespace sslpv
