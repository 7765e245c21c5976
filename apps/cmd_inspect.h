#pragma once
// `sslpv inspect`'s summary of a valid material set in the quantities an artist reads
// (albedo, mean free path, g) rather than the stored σt and σs. The grid listing and
// validation come from inspectVdbFile (volume/material/material_set.h).
#include <filesystem>
#include <ostream>

namespace sslpv {

/// Ranges over the active voxels of the (already validated) set in `file`: albedo
/// σs/σt where both grids are active, mean free path 1/σt in the file's units, g.
void printMaterialSummary(const std::filesystem::path& file, std::ostream& out);

}  // namespace sslpv
