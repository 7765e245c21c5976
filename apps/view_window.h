#pragma once
// The window of `sslpv view`: GLFW for the window and input, a Vulkan swapchain
// (gpu/vk/presenter.h) for presentation, a render thread (apps/view_worker.h) for frames.
#include <vector>

#include "apps/cmd_view.h"
#include "apps/view_script.h"
#include "volume/scene/scene.h"

namespace sslpv {

struct ViewSetup {
  Scene scene;
  LpvSettings settings;
  int width = 0, height = 0;  ///< the window's initial size
  std::vector<ScriptEvent> script;
};

/// Runs the window until it is closed (or --frames are presented). ResourceError when no
/// window can be opened or presented to.
int runViewWindow(const ViewArgs& args, ViewSetup setup);

}  // namespace sslpv
