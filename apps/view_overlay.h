#pragma once
// Text drawn into a displayed frame with a built-in 5x7 bitmap font, so the viewer's
// timings show in the window itself with no font files or text rendering library.
#include <string>
#include <vector>

namespace sslpv {

/// Draws `lines` (upper-case letters, digits and . : / - % ( ) = ^ + ; others as blanks)
/// at the top-left of an RGB8 image, white on a darkened box, scaled up on large frames.
void drawOverlay(std::vector<unsigned char>& rgb, int width, int height, const std::vector<std::string>& lines);

/// A dark RGB8 frame of `width` x `height` holding `lines` (drawOverlay): what a window
/// shows before its first image exists, so a first frame that takes seconds (a Vulkan
/// driver compiling its pipelines with an empty shader cache: ~4 s on lavapipe) reads
/// as work in progress rather than a hung, black window.
std::vector<unsigned char> noteFrame(int width, int height, const std::vector<std::string>& lines);

}  // namespace sslpv
