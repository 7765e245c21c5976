#pragma once
// Which per-step coefficients the lattice uses (docs/design.md §6.4, §6.7): a scene's
// `lpv.scheme`, chosen without pulling in the calibration itself.
#include <string>
#include <string_view>

namespace sslpv {

enum class LpvScheme { Seed, Calibrated };

/// "seed" / "calibrated"; std::nullopt-like false when unknown.
bool parseLpvScheme(std::string_view name, LpvScheme& scheme);
std::string lpvSchemeName(LpvScheme scheme);

}  // namespace sslpv
