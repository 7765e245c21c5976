#pragma once
// Resampling the material field into the LPV material grid (docs/design.md §4).
#include "volume/core/bounds.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/material/material_field.h"

namespace sslpv {

/// Fills material.sigmaT/sigmaS/g for every cell of `material.frame` with the field
/// box-filtered over the cell (TBB parallel). coverage is left as is.
void resampleMaterial(const MaterialField& field, MaterialGrid& material);

/// Re-resamples only the cells whose box overlaps `worldRegion` (a brush stroke's bounds)
/// and returns them; the whole grid when the material arrays are not yet sized to the
/// frame. The result equals a full resampleMaterial() of the new field.
CellRange resampleMaterialRegion(const MaterialField& field, MaterialGrid& material, const Bounds& worldRegion);

}  // namespace sslpv
