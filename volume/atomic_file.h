#pragma once
// Every output file is written to a temporary sibling and renamed into place, so a
// failed run never leaves a truncated or half-overwritten file behind.
#include <filesystem>
#include <functional>

namespace sslpv {

/// Fails with InputError naming `target` when its directory does not exist or is not
/// writable. Called before expensive work so a bad output path fails fast.
void requireWritableOutput(const std::filesystem::path& target);

/// Calls `write(tempPath)`, then renames tempPath over `target`. If `write` throws or
/// the rename fails, the temporary file is removed and `target` is left untouched.
void writeAtomically(const std::filesystem::path& target,
                     const std::function<void(const std::filesystem::path& tempPath)>& write);

}  // namespace sslpv
