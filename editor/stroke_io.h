#pragma once
// Stroke files: the JSON list of brush strokes `sslpv paint` applies (and an editor can
// save to replay a session). Strict like the scene: an unknown or duplicated key, a wrong
// type, a missing required key, an out-of-range value, NaN or Inf is an InputError naming
// the file and the key path, e.g. "strokes.json: strokes[2].radius: must be positive, got 0".
//
// Format (semantics of every mode, falloff and channel in editor/brush_engine.h):
//
//   {"strokes": [ STROKE, ... ]}
//
//   STROKE keys:
//   "channel"   "sigma_t" | "sigma_s" | "g" | "albedo_mfp" | "preset"; required for modes
//               set, add and multiply; optional for smooth and erase (absent: σt, σs and g
//               together). albedo_mfp and preset take mode "set" only.
//   "mode"      "set" | "add" | "multiply" | "smooth" | "erase" (required)
//   "value"     required for set, add and multiply, not allowed for smooth and erase:
//                 sigma_t, sigma_s: [r,g,b] or one number for all three, per scene unit;
//                   set: >= 0, add: any (negative subtracts), multiply: factor >= 0
//                 g: a number; set: in [-0.99, 0.99], add and multiply: any
//                 albedo_mfp: {"albedo": [r,g,b] or number in [0,1],
//                              "mean_free_path": [r,g,b] or number > 0, scene units}
//                 preset: a Jensen 2001 name ("marble", "skin1", ...), painted with g = 0
//   or, instead of "channel" and "value", the colour form (volume/material/artist_params.h; mode
//   "set", which may then be omitted):
//   "colour"    (or "color", not both) surface colour: the linear diffuse reflectance a
//               thick slab shows, [r,g,b] or one number, in [0, Cmax]; Cmax = 1 - F(0) of
//               the scene's ior (0.96 at 1.5), checked when the stroke is painted
//   "scatter_distance"  transport mean free path 1/σt', [r,g,b] or one number > 0, scene units
//   "g"         optional phase asymmetry in [-0.99, 0.99] (default 0): changes neither
//               the colour nor the distance
//   "radius"    > 0, world units (required)
//   "falloff"   "constant" | "linear" | "smooth" | "gaussian" (default "smooth")
//   "strength"  in [0, 1] (default 1)
//   "mirror"    optional {"axis": "x"|"y"|"z", "at": rest-space coordinate (default: the
//               centre of the object's rest-space bounds)}
//   "points"    [[x,y,z], ...] world-space dab path, at least one point; or
//   "rays"      [{"origin": [x,y,z], "direction": [x,y,z]}, ...] world-space rays that
//               hit the object's surface, at least one (exactly one of points and rays)
//   "depth"     rays only, optional, >= 0: also paint this far along the inward normal
//
// Example:
//   {"strokes": [{"channel": "sigma_t", "mode": "set", "value": [2, 2.5, 3], "radius": 1.5,
//                 "falloff": "smooth", "strength": 0.5, "mirror": {"axis": "x", "at": 0},
//                 "points": [[0, 0, 0], [4, 0, 0]]},
//                {"colour": [0.8, 0.35, 0.2], "scatter_distance": 2, "g": 0.3, "radius": 1,
//                 "points": [[0, 1, 0]]}]}
#include <filesystem>
#include <string>
#include <vector>

#include "editor/brush_engine.h"

namespace sslpv {

/// Parses stroke-file text; `file` names it in messages. Throws InputError.
/// With `bare`, a stroke that names no material (no "channel", "value" or colour-form key;
/// mode "set" or absent) paints that one in the colour form (`sslpv paint --colour ...`);
/// without it such a stroke is refused as before.
std::vector<Stroke> parseStrokes(const std::string& jsonText, const std::filesystem::path& file,
                                 const ArtistParams* bare = nullptr);

/// Reads and parses a stroke file. Throws InputError (unreadable file, bad content).
std::vector<Stroke> loadStrokes(const std::filesystem::path& file, const ArtistParams* bare = nullptr);

/// The stroke file for `strokes` (parseStrokes of it gives the same strokes: numbers are
/// written with 17 significant digits). Strokes with channel All omit "channel".
std::string formatStrokes(const std::vector<Stroke>& strokes);

}  // namespace sslpv
