#pragma once
// Constants of the host code's double-precision math, from the one definition the GLSL
// shares (device_shared/lpv_constants.h). The single-precision π of the GPU twins is
// sh::kPi (volume/lpv/sh.h).
#include "device_shared/lpv_constants.h"

namespace sslpv {

inline constexpr double kPi = SSLPV_PI;

}  // namespace sslpv
