#include "apps/view_script.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

#include "volume/core/error.h"

namespace sslpv {

namespace {

constexpr std::pair<const char*, ViewKey> kKeyNames[] = {
    {"q", ViewKey::Quit},          {"escape", ViewKey::Quit},          {"g", ViewKey::Grid},
    {"s", ViewKey::Steps},         {"r", ViewKey::Rerender},           {"h", ViewKey::Overlay},
    {"l", ViewKey::LightDrag},     {"space", ViewKey::PlayPause},      {"left", ViewKey::ScrubBack},
    {"right", ViewKey::ScrubForward},
};

}  // namespace

std::vector<ScriptEvent> loadViewScript(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError("--script: " + file.string() + ": cannot open");
  std::vector<ScriptEvent> events;
  std::string text;
  for (int lineNo = 1; std::getline(in, text); ++lineNo) {
    const std::string where = "--script: " + file.string() + ":" + std::to_string(lineNo) + ": ";
    if (const std::size_t hash = text.find('#'); hash != std::string::npos) text.erase(hash);
    std::istringstream line(text);
    std::string frameText, name;
    if (!(line >> frameText)) continue;
    ScriptEvent e;
    e.line = lineNo;
    if (frameText.find_first_not_of("0123456789") != std::string::npos || frameText.size() > 7)
      throw InputError(where + "expected a frame number (0 to 9999999) first, got '" + frameText + "'");
    e.frame = std::stoi(frameText);
    if (!(line >> name)) throw InputError(where + "expected an event after the frame number");
    auto number = [&](const char* what) {
      double v = 0;
      if (!(line >> v) || !std::isfinite(v)) throw InputError(where + name + ": expected a number for " + what);
      return v;
    };
    if (name == "drag") {
      std::string button;
      line >> button;
      if (button != "left" && button != "right")
        throw InputError(where + "drag: expected 'left' or 'right', got '" + button + "'");
      e.kind = ScriptEvent::Kind::Drag;
      e.rightButton = button == "right";
      e.x0 = number("x0");
      e.y0 = number("y0");
      e.x1 = number("x1");
      e.y1 = number("y1");
    } else if (name == "wheel") {
      e.kind = ScriptEvent::Kind::Wheel;
      e.wheel = number("steps");
    } else if (name == "key") {
      std::string key;
      line >> key;
      const auto* found = std::find_if(std::begin(kKeyNames), std::end(kKeyNames),
                                       [&](const auto& k) { return key == k.first; });
      if (found == std::end(kKeyNames))
        throw InputError(where + "key: unknown key '" + key + "' (g s r h l space left right q escape)");
      e.kind = ScriptEvent::Kind::Key;
      e.key = found->second;
    } else if (name == "screenshot") {
      std::string path;
      line >> path;
      if (path.empty()) throw InputError(where + "screenshot: expected a .png file");
      e.kind = ScriptEvent::Kind::Screenshot;
      e.file = path;
    } else if (name == "resize") {
      e.kind = ScriptEvent::Kind::Resize;
      const double w = number("width"), h = number("height");
      if (w < 1 || h < 1 || w > 4096 || h > 4096 || w != std::floor(w) || h != std::floor(h))
        throw InputError(where + "resize: expected whole numbers of pixels from 1 to 4096");
      e.width = int(w);
      e.height = int(h);
    } else if (name == "wait-reload") {
      e.kind = ScriptEvent::Kind::WaitReload;
    } else if (name == "wait-reload-failed") {
      e.kind = ScriptEvent::Kind::WaitReloadFailed;
    } else {
      throw InputError(where + "unknown event '" + name +
                       "' (drag, wheel, key, screenshot, wait-reload, wait-reload-failed, resize)");
    }
    std::string extra;
    if (line >> extra) throw InputError(where + "unexpected '" + extra + "' after the " + name + " event");
    events.push_back(e);
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const ScriptEvent& a, const ScriptEvent& b) { return a.frame < b.frame; });
  return events;
}

}  // namespace sslpv
