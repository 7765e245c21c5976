#pragma once
// Shared by the path tracer's tests: a sample mean with its standard error, and an empty
// material set that a test fills with the few voxels it needs.
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "volume/material/material_set.h"

namespace sslpv::test {

struct Estimate {
  double mean = 0.0;
  double standardError = 0.0;
};

/// Mean and standard error of the mean of sample(0) … sample(n − 1).
template <typename F>
Estimate estimate(int n, F&& sample) {
  double sum = 0.0, sumSq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double v = sample(i);
    sum += v;
    sumSq += v * v;
  }
  Estimate e;
  e.mean = sum / n;
  e.standardError = std::sqrt(std::max(0.0, (sumSq - n * e.mean * e.mean) / (n - 1.0)) / n);
  return e;
}

/// A material set with both required grids named and nothing active: every voxel reads
/// as the scene's base material until the test sets some.
inline std::shared_ptr<MaterialSet> emptyMaterialSet() {
  openvdb::initialize();
  auto set = std::make_shared<MaterialSet>();
  set->sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaT->setName("sigma_t");
  set->sigmaS->setName("sigma_s");
  return set;
}

}  // namespace sslpv::test
