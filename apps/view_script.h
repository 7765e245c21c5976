#pragma once
// The viewer's keys, and scripted input for headless runs (`sslpv view --script FILE`,
// hidden: tests and demos). A script line is "FRAME EVENT ARGS...", applied just before
// that presented frame (counted from 0), through the same handlers as the window's input:
//   FRAME drag left|right X0 Y0 X1 Y1   mouse drag in window pixels
//   FRAME wheel STEPS                   wheel steps (positive zooms in)
//   FRAME key NAME                      g s r h l space left right q escape
//   FRAME screenshot FILE.png           writes the last presented frame
//   FRAME wait-reload                   waits until a changed scene file is shown
//   FRAME wait-reload-failed            waits until a changed scene file fails to load
//   FRAME resize W H                    resizes the window (the frame follows)
// '#' starts a comment.
#include <filesystem>
#include <string>
#include <vector>

namespace sslpv {

enum class ViewKey { Quit, Grid, Steps, Rerender, Overlay, LightDrag, PlayPause, ScrubBack, ScrubForward };

struct ScriptEvent {
  enum class Kind { Drag, Wheel, Key, Screenshot, WaitReload, WaitReloadFailed, Resize };
  int frame = 0;
  int line = 0;  ///< in the script, for messages
  Kind kind = Kind::Key;
  bool rightButton = false;  ///< drag
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< drag
  double wheel = 0;
  int width = 0, height = 0;  ///< resize
  ViewKey key = ViewKey::Quit;
  std::filesystem::path file;  ///< screenshot
};

/// Reads a script, ordered by frame (lines of one frame keep their order). InputError
/// naming FILE:LINE on anything malformed.
std::vector<ScriptEvent> loadViewScript(const std::filesystem::path& file);

}  // namespace sslpv
