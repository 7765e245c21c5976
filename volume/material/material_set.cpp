// Material-set files: load, validate, save and inspect (docs/design.md §4 "Material sets and the material field").
// Reading goes through readVdbFileIsolated: OpenVDB's parser is not safe on corrupt files.
#include "volume/material/material_set.h"

#include <openvdb/io/File.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <mutex>
#include <ostream>
#include <set>
#include <sstream>

#include "volume/core/atomic_file.h"
#include "volume/core/error.h"
#include "volume/material/vdb_isolated_read.h"
#include "volume/scene/material.h"

namespace sslpv {
namespace {
namespace fs = std::filesystem;

/// io::File::write ignores the stream's state, so a full disk left a truncated file that
/// the atomic rename then put in place. This writes the same archive (seekable, as
/// io::File does) to a stream whose state the caller checks.
class CheckedVdbWriter : public openvdb::io::File {
 public:
  using openvdb::io::File::File;
  void writeTo(std::ostream& stream, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta) const {
    openvdb::io::Archive::write(stream, grids, /*seekable=*/true, meta);
  }
};

constexpr const char* kSigmaT = "sigma_t";
constexpr const char* kSigmaS = "sigma_s";
constexpr const char* kG = "g";
constexpr int kFormatVersion = 1;
// σs may exceed σt by float round-off (σs = albedo·σt with albedo 1 computed in float).
constexpr double kAlbedoTolerance = 1e-6;

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.7g", v);
  return text;
}

std::string vec(double x, double y, double z) { return "(" + number(x) + ", " + number(y) + ", " + number(z) + ")"; }
std::string vec(const openvdb::Vec3s& v) { return vec(v[0], v[1], v[2]); }
std::string vec(const openvdb::Vec3d& v) { return vec(v[0], v[1], v[2]); }
std::string coord(const openvdb::Coord& c) {
  return "(" + std::to_string(c.x()) + "," + std::to_string(c.y()) + "," + std::to_string(c.z()) + ")";
}

/// The OpenVDB C++ name of a grid's type, as users know it from the API.
std::string gridTypeName(const openvdb::GridBase& grid) {
  if (grid.isType<openvdb::FloatGrid>()) return "FloatGrid";
  if (grid.isType<openvdb::DoubleGrid>()) return "DoubleGrid";
  if (grid.isType<openvdb::Int32Grid>()) return "Int32Grid";
  if (grid.isType<openvdb::Int64Grid>()) return "Int64Grid";
  if (grid.isType<openvdb::BoolGrid>()) return "BoolGrid";
  if (grid.isType<openvdb::MaskGrid>()) return "MaskGrid";
  if (grid.isType<openvdb::Vec3SGrid>()) return "Vec3SGrid";
  if (grid.isType<openvdb::Vec3DGrid>()) return "Vec3DGrid";
  if (grid.isType<openvdb::Vec3IGrid>()) return "Vec3IGrid";
  return grid.type() + " (value type " + grid.valueType() + ")";
}

/// Collects problems, each prefixed with the file, up to a limit.
class ProblemList {
 public:
  ProblemList(std::string file, std::size_t limit) : file_(std::move(file)), limit_(limit) {}
  bool full() const { return problems_.size() >= limit_; }
  void add(const std::string& message) {
    if (!full()) problems_.push_back({file_ + ": " + message});
  }
  std::vector<ValidationProblem> take() { return std::move(problems_); }

 private:
  std::string file_;
  std::size_t limit_;
  std::vector<ValidationProblem> problems_;
};

/// "grid 'sigma_t' voxel (3,4,5) at world (0.3, 0.4, 0.5)" or, for an active tile,
/// "grid 'sigma_t' tile of 8x8x8 voxels at (0,0,0), world (0, 0, 0)".
template <class IterT>
std::string location(const std::string& gridName, const openvdb::GridBase& grid, const IterT& item) {
  const openvdb::Coord origin = item.getCoord();
  const std::string world = vec(grid.indexToWorld(origin));
  if (item.isVoxelValue()) return "grid '" + gridName + "' voxel " + coord(origin) + " at world " + world;
  openvdb::CoordBBox box;
  item.getBoundingBox(box);
  const openvdb::Coord dim = box.dim();
  return "grid '" + gridName + "' tile of " + std::to_string(dim.x()) + "x" + std::to_string(dim.y()) + "x" +
         std::to_string(dim.z()) + " voxels at " + coord(origin) + ", world " + world;
}

// Each check returns what is wrong with one value, or "" when it is valid.
std::string sigmaProblem(const std::string& gridName, const openvdb::Vec3s& v) {
  static const char kChannel[] = "rgb";
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(v[c])) return gridName + " " + vec(v) + " is not finite";
  for (int c = 0; c < 3; ++c)
    if (v[c] < 0.0f) return gridName + " " + vec(v) + " is negative in channel " + kChannel[c];
  return {};
}

std::string gProblem(float g) {
  if (!std::isfinite(g)) return "g = " + number(g) + " is not finite";
  if (std::abs(g) >= 1.0f) return "g = " + number(g) + ", but |g| must be below 1";
  return {};
}

std::string albedoProblem(const openvdb::Vec3s& sigmaS, const openvdb::Vec3s& sigmaT) {
  static const char kChannel[] = "rgb";
  for (int c = 0; c < 3; ++c)
    if (double(sigmaS[c]) > double(sigmaT[c]) * (1.0 + kAlbedoTolerance))
      return "sigma_s " + vec(sigmaS) + " exceeds sigma_t " + vec(sigmaT) + " in channel " + kChannel[c] +
             " (albedo > 1)";
  return {};
}

template <class GridT, class Check>
void checkValues(const GridT& grid, const std::string& gridName, Check check, ProblemList& problems) {
  if (std::string p = check(grid.background()); !p.empty()) problems.add("grid '" + gridName + "' background: " + p);
  for (auto item = grid.cbeginValueOn(); item && !problems.full(); ++item)
    if (std::string p = check(*item); !p.empty()) problems.add(location(gridName, grid, item) + ": " + p);
}

/// σs <= σt where both grids hold an active value at the same index (same transform).
/// Values are voxels or tiles of different sizes; every overlapping pair is compared
/// once, located at the finer of the two.
void checkAlbedo(const openvdb::Vec3SGrid& sigmaT, const openvdb::Vec3SGrid& sigmaS, ProblemList& problems) {
  if (std::string p = albedoProblem(sigmaS.background(), sigmaT.background()); !p.empty())
    problems.add("grids 'sigma_s' and 'sigma_t' backgrounds: " + p);
  if (sigmaT.constTransform() != sigmaS.constTransform()) return;
  auto accessorT = sigmaT.getConstAccessor();
  auto accessorS = sigmaS.getConstAccessor();
  // σt value covering the whole σs item (same or coarser level; depth 0 = root).
  for (auto item = sigmaS.cbeginValueOn(); item && !problems.full(); ++item) {
    openvdb::Vec3s t;
    if (!accessorT.probeValue(item.getCoord(), t)) continue;
    if (accessorT.getValueDepth(item.getCoord()) > int(item.getDepth())) continue;
    if (std::string p = albedoProblem(*item, t); !p.empty()) problems.add(location(kSigmaS, sigmaS, item) + ": " + p);
  }
  // σt items strictly inside a coarser σs tile.
  for (auto item = sigmaT.cbeginValueOn(); item && !problems.full(); ++item) {
    openvdb::Vec3s s;
    if (!accessorS.probeValue(item.getCoord(), s)) continue;
    if (accessorS.getValueDepth(item.getCoord()) >= int(item.getDepth())) continue;
    if (std::string p = albedoProblem(s, *item); !p.empty()) problems.add(location(kSigmaS, sigmaT, item) + ": " + p);
  }
}

/// Voxel edge lengths (file units) of a material grid. Zero, NaN or Inf make the grid's
/// index<->world maps singular (OpenVDB throws ArithmeticError deep inside resampling);
/// beyond the range, voxel positions leave the scene's coordinate range or collapse in
/// float.
constexpr double kMinVoxelSize = 1e-6;
constexpr double kMaxVoxelSize = 1e6;

/// What is wrong with the grid's transform, or "" when it is usable. The axes come from
/// applying the map, not from getAffineMap(), which itself throws on a singular matrix.
std::string transformProblem(const openvdb::GridBase& grid) {
  const openvdb::math::Transform& transform = grid.constTransform();
  const openvdb::math::MapBase::ConstPtr map = transform.baseMap();
  if (!map || !transform.isLinear())
    return "grid '" + grid.getName() + "' has a " + (map ? transform.mapType() : std::string("missing")) +
           " transform, expected a linear one (scale, rotation, translation)";
  openvdb::Vec3d origin(0.0), size(0.0);
  openvdb::Mat3d axes;
  bool usable = true;
  try {
    origin = map->applyMap(openvdb::Vec3d(0.0));
    for (int axis = 0; axis < 3; ++axis) {
      openvdb::Vec3d unit(0.0);
      unit[axis] = 1.0;
      const openvdb::Vec3d edge = map->applyMap(unit) - origin;
      axes.setRow(axis, edge);
      size[axis] = edge.length();
    }
  } catch (const openvdb::Exception&) {
    usable = false;
  }
  const double det = axes.det();
  for (int axis = 0; axis < 3; ++axis)
    usable = usable && std::isfinite(origin[axis]) && size[axis] >= kMinVoxelSize && size[axis] <= kMaxVoxelSize;
  // Sheared to a plane: every edge in range, yet no volume.
  usable = usable && std::abs(det) >= 1e-6 * size[0] * size[1] * size[2];
  if (usable) return {};
  return "grid '" + grid.getName() + "' has voxel size " + vec(size) + " (origin " + vec(origin) +
         "); each voxel edge must be in [" + number(kMinVoxelSize) + ", " + number(kMaxVoxelSize) +
         "] file units, and the voxels must not be flat";
}

/// The file's grids and metadata read as a material set, with the problems that are
/// not about values (wrong types, duplicate names, units).
struct InterpretedFile {
  MaterialSet set;
  bool unitsAssumed = false;
  std::vector<std::string> structural;
  std::set<std::string> wrongType;  ///< required grids present with another type
};

InterpretedFile interpret(const VdbContents& contents) {
  InterpretedFile result;
  std::set<std::string> seen;
  for (const openvdb::GridBase::Ptr& grid : *contents.grids) {
    if (!grid) continue;
    const std::string name = grid->getName();
    const bool required = name == kSigmaT || name == kSigmaS;
    if (!required && name != kG) continue;
    if (!seen.insert(name).second) {
      result.structural.push_back("more than one grid is named '" + name + "'");
      continue;
    }
    if (std::string problem = transformProblem(*grid); !problem.empty()) {
      result.structural.push_back(problem);
      result.wrongType.insert(name);  // its values are not checked either
      continue;
    }
    const char* expected = required ? "Vec3SGrid" : "FloatGrid";
    if (required && grid->isType<openvdb::Vec3SGrid>()) {
      (name == kSigmaT ? result.set.sigmaT : result.set.sigmaS) = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid);
    } else if (!required && grid->isType<openvdb::FloatGrid>()) {
      result.set.g = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
    } else {
      result.structural.push_back("grid '" + name + "' is " + gridTypeName(*grid) + ", expected " + expected);
      result.wrongType.insert(name);
    }
  }

  const openvdb::MetaMap& meta = *contents.metadata;
  if (openvdb::Metadata::ConstPtr units = meta["units"]) {
    auto text = openvdb::DynamicPtrCast<const openvdb::StringMetadata>(units);
    if (!text || !unitInMm(text->value()))
      result.structural.push_back("metadata 'units' is " + units->typeName() + " '" + units->str() +
                                  "', expected the string mm, cm, m or in");
    else
      result.set.units = text->value();
  } else {
    result.unitsAssumed = true;  // missing units mean millimetres (docs/design.md §4)
  }
  if (openvdb::Metadata::ConstPtr creator = meta["creator"]) result.set.creator = creator->str();
  return result;
}

std::vector<ValidationProblem> validate(const MaterialSet& set, const std::string& file, std::size_t maxProblems,
                                        const std::set<std::string>& alreadyReported) {
  ProblemList problems(file, maxProblems);
  if (!set.sigmaT && !alreadyReported.count(kSigmaT))
    problems.add("missing required grid 'sigma_t' (Vec3SGrid, extinction per unit length)");
  if (!set.sigmaS && !alreadyReported.count(kSigmaS))
    problems.add("missing required grid 'sigma_s' (Vec3SGrid, scattering per unit length)");
  if (set.sigmaT)
    checkValues(
        *set.sigmaT, kSigmaT, [](const openvdb::Vec3s& v) { return sigmaProblem(kSigmaT, v); }, problems);
  if (set.sigmaS)
    checkValues(
        *set.sigmaS, kSigmaS, [](const openvdb::Vec3s& v) { return sigmaProblem(kSigmaS, v); }, problems);
  if (set.g) checkValues(*set.g, kG, gProblem, problems);
  if (set.sigmaT && set.sigmaS && !problems.full()) checkAlbedo(*set.sigmaT, *set.sigmaS, problems);
  return problems.take();
}

std::vector<ValidationProblem> allProblems(const InterpretedFile& file, const std::string& name,
                                           std::size_t maxProblems) {
  std::vector<ValidationProblem> problems;
  for (const std::string& p : file.structural)
    if (problems.size() < maxProblems) problems.push_back({name + ": " + p});
  for (ValidationProblem& p : validate(file.set, name, maxProblems - problems.size(), file.wrongType))
    problems.push_back(std::move(p));
  return problems;
}

}  // namespace

void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

std::shared_ptr<const MaterialSet> loadMaterialSet(const fs::path& file) {
  const VdbContents contents = readVdbFileIsolated(file);
  InterpretedFile interpreted = interpret(contents);
  const std::vector<ValidationProblem> problems = allProblems(interpreted, file.string(), 1);
  if (!problems.empty()) throw InputError(problems.front().message);
  return std::make_shared<const MaterialSet>(std::move(interpreted.set));
}

std::vector<ValidationProblem> validateMaterialSet(const MaterialSet& set, const std::string& fileForMessages,
                                                   std::size_t maxProblems) {
  return validate(set, fileForMessages, maxProblems, {});
}

void saveMaterialSet(const MaterialSet& set, const fs::path& file) {
  initializeOpenVdb();
  const std::string name = file.string();
  if (!set.sigmaT || !set.sigmaS)
    throw InputError(name + ": cannot save a material set without both 'sigma_t' and 'sigma_s' grids");
  if (!unitInMm(set.units))
    throw InputError(name + ": cannot save units '" + set.units + "', expected mm, cm, m or in");
  openvdb::GridCPtrVec grids;
  // Shallow copies (shared trees, own metadata) carry the contract's names without
  // renaming the caller's grids.
  auto addNamed = [&grids](const openvdb::GridBase::ConstPtr& grid, const char* gridName) {
    openvdb::GridBase::Ptr copy = openvdb::ConstPtrCast<openvdb::GridBase>(grid->copyGrid());
    copy->setName(gridName);
    grids.push_back(copy);
  };
  addNamed(set.sigmaT, kSigmaT);
  addNamed(set.sigmaS, kSigmaS);
  if (set.g) addNamed(set.g, kG);
  openvdb::MetaMap meta;
  meta.insertMeta("units", openvdb::StringMetadata(set.units));
  meta.insertMeta("creator", openvdb::StringMetadata(set.creator.empty() ? "sslpv" : set.creator));
  meta.insertMeta("version", openvdb::Int32Metadata(kFormatVersion));
  writeAtomically(file, [&](const fs::path& temp) {
    std::ofstream stream(temp, std::ios::binary | std::ios::trunc);
    if (!stream) throw InputError(name + ": cannot write the VDB file: cannot create " + temp.string());
    try {
      CheckedVdbWriter(temp.string()).writeTo(stream, grids, meta);
    } catch (const openvdb::Exception& e) {
      throw InputError(name + ": cannot write the VDB file: " + e.what());
    }
    stream.close();
    if (stream.fail()) throwWriteFailed(file, errno);
  });
}

namespace {

/// Per-channel min/max of the active values (voxels and tiles) of numeric grids.
template <class GridT>
bool printValueRange(const openvdb::GridBase& base, std::ostream& out) {
  const auto* grid = dynamic_cast<const GridT*>(&base);
  if (!grid) return false;
  using Value = typename GridT::ValueType;
  using Traits = openvdb::VecTraits<Value>;
  constexpr int kChannels = Traits::IsVec ? Traits::Size : 1;
  auto channel = [](const Value& v, int c) -> double {
    if constexpr (Traits::IsVec)
      return double(v[c]);
    else
      return double(v);
  };
  double lo[kChannels], hi[kChannels];
  std::fill(lo, lo + kChannels, std::numeric_limits<double>::infinity());
  std::fill(hi, hi + kChannels, -std::numeric_limits<double>::infinity());
  bool any = false;
  for (auto item = grid->cbeginValueOn(); item; ++item) {
    any = true;
    for (int c = 0; c < kChannels; ++c) {
      lo[c] = std::min(lo[c], channel(*item, c));
      hi[c] = std::max(hi[c], channel(*item, c));
    }
  }
  out << "  value range (active):";
  if (!any) out << " none";
  static const char* kNames[] = {"r", "g", "b"};
  for (int c = 0; any && c < kChannels; ++c)
    out << (c ? "," : "") << " " << (kChannels == 3 ? kNames[c] : "") << (kChannels == 3 ? " " : "") << "["
        << number(lo[c]) << ", " << number(hi[c]) << "]";
  out << "\n  background: ";
  if constexpr (Traits::IsVec) {
    out << "(";
    for (int c = 0; c < kChannels; ++c) out << (c ? ", " : "") << number(channel(grid->background(), c));
    out << ")";
  } else {
    out << number(channel(grid->background(), 0));
  }
  out << "\n";
  return true;
}

std::string gridRole(const std::string& name) {
  if (name == kSigmaT) return "sslpv: extinction per unit length, RGB (required, Vec3SGrid)";
  if (name == kSigmaS) return "sslpv: scattering per unit length, RGB (required, Vec3SGrid)";
  if (name == kG) return "sslpv: Henyey-Greenstein asymmetry (optional, FloatGrid)";
  return "not used by sslpv";
}

void printGrid(const openvdb::GridBase& grid, std::ostream& out) {
  out << "grid '" << grid.getName() << "': " << gridTypeName(grid) << ", " << gridRole(grid.getName()) << "\n";
  const openvdb::TreeBase& tree = grid.baseTree();
  out << "  active voxels: " << tree.activeVoxelCount() << " (" << tree.activeLeafVoxelCount()
      << " in leaves), active tiles: " << tree.activeTileCount() << "\n";
  if (!printValueRange<openvdb::Vec3SGrid>(grid, out) && !printValueRange<openvdb::FloatGrid>(grid, out) &&
      !printValueRange<openvdb::DoubleGrid>(grid, out) && !printValueRange<openvdb::Vec3DGrid>(grid, out) &&
      !printValueRange<openvdb::Int32Grid>(grid, out) && !printValueRange<openvdb::Int64Grid>(grid, out) &&
      !printValueRange<openvdb::Vec3IGrid>(grid, out))
    out << "  value range: not shown for this type\n";
  const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  const openvdb::math::Transform& transform = grid.constTransform();
  if (box.empty()) {
    out << "  index bounding box: empty\n";
  } else {
    out << "  index bounding box: " << coord(box.min()) << " .. " << coord(box.max()) << "\n";
  }
  const std::string problem = transformProblem(grid);
  if (!problem.empty()) {
    // Printing a singular map builds its (impossible) affine inverse and throws.
    out << "  transform (" << transform.mapType() << "): unusable, see validation\n";
    return;
  }
  out << "  transform (" << transform.mapType() << "):\n";
  std::ostringstream transformText;
  transform.print(transformText, "    ");
  out << transformText.str();
  if (!transformText.str().empty() && transformText.str().back() != '\n') out << "\n";
  if (!box.empty()) {
    // Voxel (i,j,k) covers index [i-0.5, i+0.5]: its centre is at the index coordinate.
    const openvdb::BBoxd world = transform.indexToWorld(
        openvdb::BBoxd(box.min().asVec3d() - openvdb::Vec3d(0.5), box.max().asVec3d() + openvdb::Vec3d(0.5)));
    out << "  world bounding box: " << vec(world.min()) << " .. " << vec(world.max()) << "\n";
  }
}

}  // namespace

bool inspectVdbFile(const fs::path& file, std::ostream& report) {
  constexpr std::size_t kMaxReported = 100;
  const std::string name = file.string();
  const VdbContents contents = readVdbFileIsolated(file);
  const InterpretedFile interpreted = interpret(contents);

  report << "file: " << name << "\n";
  report << "metadata:\n";
  for (auto item = contents.metadata->beginMeta(); item != contents.metadata->endMeta(); ++item)
    report << "  " << item->first << " (" << item->second->typeName() << "): " << item->second->str() << "\n";
  if (interpreted.unitsAssumed) report << "  units: not in the file, assumed mm\n";
  report << "grids: " << contents.grids->size() << "\n";
  for (const openvdb::GridBase::Ptr& grid : *contents.grids)
    if (grid) printGrid(*grid, report);

  const std::vector<ValidationProblem> problems = allProblems(interpreted, name, kMaxReported);
  if (problems.empty()) {
    report << "validation: OK\n";
    return true;
  }
  report << "validation: " << problems.size()
         << (problems.size() == kMaxReported ? " problems (stopped at the first 100)"
             : problems.size() == 1          ? " problem"
                                             : " problems")
         << "\n";
  for (const ValidationProblem& p : problems) report << "  " << p.message << "\n";
  return false;
}

std::shared_ptr<MaterialSet> deepCopy(const MaterialSet& set) {
  auto copy = std::make_shared<MaterialSet>(set);
  copy->sigmaT = set.sigmaT->deepCopy();
  copy->sigmaS = set.sigmaS->deepCopy();
  if (set.g) copy->g = set.g->deepCopy();
  return copy;
}

}  // namespace sslpv
