#pragma once
// Voxel-for-voxel comparison of material sets, for the editor's save/recovery tests.
#include <gtest/gtest.h>

#include <cstring>

#include "volume/material/material_set.h"

namespace sslpv::test {

template <class GridT>
inline ::testing::AssertionResult sameGrid(const GridT* a, const GridT* b, const char* name) {
  if (!a || !b) return a == b ? ::testing::AssertionSuccess() : ::testing::AssertionFailure() << name << " missing";
  if (a->activeVoxelCount() != b->activeVoxelCount())
    return ::testing::AssertionFailure() << name << ": active voxel counts " << a->activeVoxelCount() << " vs "
                                         << b->activeVoxelCount();
  if (!(a->transform() == b->transform())) return ::testing::AssertionFailure() << name << ": transforms differ";
  auto accB = b->getConstAccessor();
  for (auto it = a->cbeginValueOn(); it; ++it) {
    typename GridT::ValueType vb;
    const typename GridT::ValueType va = *it;
    if (!accB.probeValue(it.getCoord(), vb) || std::memcmp(&va, &vb, sizeof va) != 0)
      return ::testing::AssertionFailure() << name << " voxel " << it.getCoord() << " differs";
  }
  return ::testing::AssertionSuccess();
}

/// Active states and stored bits of every active voxel of all three grids are identical.
inline ::testing::AssertionResult sameVoxels(const MaterialSet& a, const MaterialSet& b) {
  if (auto r = sameGrid(a.sigmaT.get(), b.sigmaT.get(), "sigma_t"); !r) return r;
  if (auto r = sameGrid(a.sigmaS.get(), b.sigmaS.get(), "sigma_s"); !r) return r;
  return sameGrid(a.g.get(), b.g.get(), "g");
}

}  // namespace sslpv::test
