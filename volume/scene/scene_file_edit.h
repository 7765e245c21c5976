#pragma once
// Changing one value of a scene file the way a person would with a text editor: every
// other byte (indentation, number spelling, key order, line breaks) stays as it was, so a
// hand-formatted 15-line scene is still 15 lines after the editor or `sslpv paint
// --update-scene` records its material set or camera.
#include <filesystem>
#include <string>
#include <vector>

#include "volume/core/atomic_file.h"

namespace sslpv {

/// `text`, a JSON document whose top level is an object, with the value at `keyPath`
/// (object keys from the top, e.g. {"material", "vdb"}) replaced by `valueJson` (JSON
/// text, inserted as given). A missing last key is added as the last member of its
/// object, laid out like the member before it. Throws InputError naming `file` and the
/// key path when the text is not JSON or an intermediate key is missing or not an object.
std::string spliceJsonValue(const std::string& text, const std::vector<std::string>& keyPath,
                            const std::string& valueJson, const std::filesystem::path& file);

/// The scene text `original` of `sceneFile` with material.vdb naming `vdb` (see
/// scenePathValue), checked to load as a scene: a scene edited on disk meanwhile into
/// something invalid is refused (InputError) rather than overwritten with it.
std::string sceneTextNamingVdb(const std::filesystem::path& sceneFile, const std::string& original,
                               const std::filesystem::path& vdb);

/// Writes `text` as `sceneFile`: one part of writeAtomicallyTogether, so a scene never
/// names a material set that failed to be written (or the reverse).
AtomicOutput sceneTextOutput(const std::filesystem::path& sceneFile, std::string text);

/// A path as the scene's material.vdb names it: relative to the scene file's folder
/// when it can be (forward slashes), so the scene folder can move as a whole.
std::string scenePathValue(const std::filesystem::path& sceneFile, const std::filesystem::path& target);

}  // namespace sslpv
