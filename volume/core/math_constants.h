#pragma once
// Constants of the host code's double-precision math. The single-precision π the GPU twins
// share is sh::kPi (volume/lpv/sh.h, from lpv_constants.h's SSLPV_PI).

namespace sslpv {

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace sslpv
