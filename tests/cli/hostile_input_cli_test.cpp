// The `sslpv` binary against hostile input, end to end: numbers that are finite but huge,
// files that are not regular files (FIFOs, devices, /proc), NUL bytes in paths, singular
// material-set transforms, a full disk and signals. Every run is bounded by `timeout`, so
// a reader that blocks fails the test instead of hanging it.
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>

#include "cli_rejects.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// A closed axis-aligned box of half-side `half` as OBJ text, after `header` lines.
std::string boxObj(double half, const std::string& header = "") {
  std::string text = header;
  for (int i = 0; i < 8; ++i)
    text += "v " + std::to_string((i & 1) ? half : -half) + " " + std::to_string((i & 2) ? half : -half) + " " +
            std::to_string((i & 4) ? half : -half) + "\n";
  // The faces of mesh.cpp's box, 1-based, counter-clockwise seen from outside.
  text += "f 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\n";
  return text;
}

class HostileInput : public CliRejects {
 protected:
  /// run() under `timeout`: a blocked reader is killed and reported as exit code 137.
  RunResult runBounded(const std::vector<std::string>& args, int seconds = 60) {
    filesBefore_ = listing();
    std::vector<std::string> command{"timeout", "-s", "KILL", std::to_string(seconds), SSLPV_BINARY};
    command.insert(command.end(), args.begin(), args.end());
    return runProgram(command);
  }

  RunResult renderBounded(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{"render", scenePath().string(), "-o", out().string(), "--backend", "cpu"};
    args.insert(args.end(), extra.begin(), extra.end());
    return runBounded(args);
  }

  fs::path makeFifo(const std::string& name) {
    const fs::path fifo = dir_ / name;
    if (::mkfifo(fifo.c_str(), 0644) != 0) ADD_FAILURE() << "mkfifo " << fifo << ": " << std::strerror(errno);
    return fifo;
  }
};

// --- item: huge finite numbers -----------------------------------------------------------

TEST_F(HostileInput, HugeLightPositionNamesTheKeyAndTheRange) {
  json scene = smallScene();
  scene["lights"][0]["position"] = json::parse("[40, 9223372036854775808, -50]");
  writeScene(scene);
  expectRejected(renderBounded(), {"scene.json", "lights[0].position[1]", "1000000"});
}

TEST_F(HostileInput, EveryNumericSceneKeyIsRangeChecked) {
  // Each value is finite and passed the old checks (sign, open intervals), yet overflows
  // float somewhere downstream.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/mesh/min/0", "-2e6"},
      {"/mesh/max/2", "1e300"},
      {"/lights/0/intensity/1", "1e30"},
      {"/material/base/sigma_t/0", "1e20"},
      {"/camera/position/2", "1e7"},
      {"/camera/target/0", "-1e9"},
      {"/camera/up/1", "1e300"},
      {"/transform/translate/0", "2147483648"},
      {"/transform/rotate_deg/2", "1e300"},
      {"/transform/scale", "1e-30"},
      {"/transform/scale", "1e30"},
  };
  for (const auto& [pointer, value] : cases) {
    SCOPED_TRACE(pointer + " = " + value);
    json scene = smallScene();
    scene["transform"] = {{"translate", {0, 0, 0}}, {"rotate_deg", {0, 0, 0}}, {"scale", 1}};
    scene[json::json_pointer(pointer)] = json::parse(value);
    writeScene(scene);
    // "/mesh/min/0" -> "mesh.min[0]"
    std::string keyPath;
    std::string rest = pointer.substr(1);
    for (std::size_t at = 0; at <= rest.size();) {
      const std::size_t slash = std::min(rest.find('/', at), rest.size());
      const std::string part = rest.substr(at, slash - at);
      keyPath += std::isdigit(static_cast<unsigned char>(part[0])) ? "[" + part + "]" : (keyPath.empty() ? "" : ".") + part;
      at = slash + 1;
    }
    expectRejected(renderBounded(), {"scene.json", keyPath, "must be in ["});
  }
}

TEST_F(HostileInput, SpotAndDirectionalLightsAreRangeChecked) {
  json scene = smallScene();
  scene["lights"] = json::parse(R"([{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1e13]}])");
  writeScene(scene);
  expectRejected(renderBounded(), {"scene.json", "lights[0].irradiance[2]", "1e+12"});
  scene["lights"] = json::parse(
      R"([{"type": "spot", "position": [0, 30, 0], "direction": [0, 1e-9, 0], "fov_deg": 30, "intensity": [1, 1, 1]}])");
  writeScene(scene);
  expectRejected(renderBounded(), {"scene.json", "lights[0].direction", "length at least"});
}

TEST_F(HostileInput, HugeExposureIsRejectedBeforeRendering) {
  writeScene(smallScene());
  expectRejected(renderBounded({"--exposure", "1e38"}), {"--exposure", "1000000"});
  expectRejected(renderBounded({"--exposure", "1e-30"}), {"--exposure"});
}

TEST_F(HostileInput, MeshVertexBeyondTheCoordinateRangeNamesTheMesh) {
  writeText(dir_ / "big.obj", boxObj(5e5));
  json scene = smallScene();
  scene["mesh"] = {{"path", "big.obj"}};
  scene["transform"] = {{"scale", 4}};  // vertices at 2e6
  writeScene(scene);
  expectRejected(renderBounded(), {"scene.json", "mesh.path", "big.obj", "coordinate range"});
}

TEST_F(HostileInput, TranslatedPrimitiveBeyondTheCoordinateRangeNamesSceneAndMesh) {
  json scene = smallScene();
  scene["mesh"] = json::parse(R"({"primitive": "box", "min": [999990, 0, 0], "max": [1000000, 10, 10]})");
  scene["transform"] = {{"translate", {100, 0, 0}}};
  writeScene(scene);
  expectRejected(renderBounded(), {"scene.json", "mesh: box", "coordinate range"});
}

// --- item: files that are not regular files ----------------------------------------------

TEST_F(HostileInput, SceneThatIsAFifoIsRefusedNotWaitedOn) {
  const fs::path fifo = makeFifo("scene.fifo");
  const RunResult r = runBounded({"render", fifo.string(), "-o", out().string(), "--backend", "cpu"});
  expectRejected(r, {"scene.fifo", "FIFO"});
}

TEST_F(HostileInput, SceneThatIsADeviceIsRefused) {
  const RunResult r = runBounded({"render", "/dev/zero", "-o", out().string(), "--backend", "cpu"});
  expectRejected(r, {"/dev/zero", "character device"});
}

TEST_F(HostileInput, OversizedSceneNamesTheLimit) {
  // Sparse: no disk space is used for the zeros.
  writeText(scenePath(), "");
  fs::resize_file(scenePath(), (std::uintmax_t(64) << 20) + 1);
  expectRejected(renderBounded(), {"scene.json", "64 MiB"});
}

TEST_F(HostileInput, MaterialSetThatIsNotARegularFileIsRefused) {
  const fs::path fifo = makeFifo("set.vdb");
  for (const std::string& vdb : {fifo.string(), std::string("/dev/urandom"), std::string("/proc/self/mem")}) {
    SCOPED_TRACE(vdb);
    writeSceneWithVdb(vdb);
    expectRejected(renderBounded(), {vdb, "not a regular file"});
    expectRejected(runBounded({"inspect", vdb}), {vdb, "not a regular file"});
  }
}

TEST_F(HostileInput, MeshThatIsNotARegularFileIsRefused) {
  const fs::path fifo = makeFifo("mesh.obj");
  for (const std::string& mesh : {fifo.string(), std::string("/dev/zero")}) {
    SCOPED_TRACE(mesh);
    json scene = smallScene();
    scene["mesh"] = {{"path", mesh}};
    writeScene(scene);
    expectRejected(renderBounded(), {mesh, "not a regular file"});
  }
}

TEST_F(HostileInput, ObjMaterialLibraryThatIsAFifoIsRefused) {
  makeFifo("looks.mtl");
  writeText(dir_ / "box.obj", boxObj(5.0, "mtllib looks.mtl\nusemtl skin\n"));
  json scene = smallScene();
  scene["mesh"] = {{"path", "box.obj"}};
  writeScene(scene);
  expectRejected(renderBounded(), {"looks.mtl", "FIFO"});
}

TEST_F(HostileInput, ObjWithMissingMaterialLibraryStillRenders) {
  // The side-file check must not turn assimp's tolerated missing .mtl into an error.
  writeText(dir_ / "box.obj", boxObj(5.0, "mtllib absent.mtl\nusemtl skin\n"));
  json scene = smallScene();
  scene["mesh"] = {{"path", "box.obj"}};
  writeScene(scene);
  const RunResult r = renderBounded();
  EXPECT_EQ(r.exitCode, 0) << r.stderrText;
}

TEST_F(HostileInput, StrokeFileThatIsAFifoIsRefused) {
  writeScene(smallScene());
  const fs::path fifo = makeFifo("strokes.json");
  const RunResult r =
      runBounded({"paint", scenePath().string(), "--strokes", fifo.string(), "-o", (dir_ / "out.vdb").string()});
  expectRejected(r, {"strokes.json", "FIFO"});
}

TEST_F(HostileInput, ImageToCompareThatIsAFifoIsRefusedAsSuch) {
  const fs::path fifo = makeFifo("a.pfm");
  writeText(dir_ / "b.pfm", "PF\n1 1\n-1.0\n" + std::string(12, '\0'));
  expectRejected(runBounded({"compare", fifo.string(), (dir_ / "b.pfm").string()}), {"a.pfm", "FIFO"});
}

// --- item: NUL in a path -----------------------------------------------------------------

TEST_F(HostileInput, NulInsideMeshPathIsRefused) {
  writeText(dir_ / "box.obj", boxObj(5.0));
  json scene = smallScene();
  scene["mesh"] = {{"path", std::string("box.obj\0.png", 12)}};
  writeScene(scene);
  expectRejected(renderBounded(), {"scene.json", "mesh.path", "NUL"});
}

TEST_F(HostileInput, NulInsideMaterialSetPathIsRefused) {
  writeVdb(dir_ / "set.vdb", validGrids());
  writeSceneWithVdb(std::string("set.vdb\0x", 9));
  expectRejected(renderBounded(), {"scene.json", "material.vdb", "NUL"});
}

// --- item: singular material-set transforms ----------------------------------------------

/// `validGrids()` written with voxel size 0.5, then the three scale doubles of every
/// grid's map patched to `size` in the file's bytes: OpenVDB refuses to create such maps,
/// but a file can hold them.
void writeVdbWithVoxelSize(const fs::path& file, double size) {
  MaterialGrids grids = validGrids();
  for (openvdb::GridBase::Ptr grid : openvdb::GridPtrVec{grids.sigmaT, grids.sigmaS, grids.g})
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  writeVdb(file, grids);
  std::string bytes = readText(file);
  const double half[3] = {0.5, 0.5, 0.5};
  const double patched[3] = {size, size, size};
  const std::string from(reinterpret_cast<const char*>(half), sizeof half);
  const std::string to(reinterpret_cast<const char*>(patched), sizeof patched);
  int replaced = 0;
  for (std::size_t at = bytes.find(from); at != std::string::npos; at = bytes.find(from, at + to.size())) {
    bytes.replace(at, to.size(), to);
    ++replaced;
  }
  ASSERT_GE(replaced, 3) << "the scale of every grid's map should be in the file";
  writeText(file, bytes);
}

TEST_F(HostileInput, SingularVoxelSizeNamesFileGridAndSize) {
  for (const double size : {1e-9, 0.0, std::nan(""), HUGE_VAL}) {
    SCOPED_TRACE(size);
    writeVdbWithVoxelSize(dir_ / "bad.vdb", size);
    writeSceneWithVdb("bad.vdb");
    const RunResult rendered = renderBounded();
    expectRejected(rendered, {"bad.vdb", "voxel size"});
    EXPECT_TRUE(mentionsWord(rendered.stderrText, "sigma_t")) << rendered.stderrText;
    const RunResult inspected = runBounded({"inspect", (dir_ / "bad.vdb").string()});
    EXPECT_EQ(inspected.exitCode, 2) << inspected.stderrText;
    EXPECT_NE(inspected.stdoutText.find("voxel size"), std::string::npos) << inspected.stdoutText;
    EXPECT_EQ(inspected.stderrText.find("internal error"), std::string::npos) << inspected.stderrText;
  }
}

// --- out of memory ------------------------------------------------------------------------

TEST_F(HostileInput, OutOfMemoryNamesTheCommandAndItsInput) {
  if (runProgram({"prlimit", "--version"}).exitCode != 0) GTEST_SKIP() << "prlimit (util-linux) is not installed";
  writeScene(smallScene());
  // A 256-cell grid needs well over the 400 MiB of address space allowed here.
  const RunResult r = runProgram({"prlimit", "--as=" + std::to_string(400u << 20), SSLPV_BINARY, "render",
                                  scenePath().string(), "-o", out().string(), "--backend", "cpu", "--grid", "256"});
  EXPECT_EQ(r.signal, 0);
  EXPECT_EQ(r.exitCode, 3) << r.stderrText;
  EXPECT_NE(r.stderrText.find("sslpv: error: render " + scenePath().string() + ": out of memory"), std::string::npos)
      << r.stderrText;
  EXPECT_EQ(readText(out()), kPreexistingOutput);
}

// --- item: full disk and interrupted runs ------------------------------------------------

/// A 64 KiB tmpfs at dir/small, unmounted when the object goes away; skipped (loudly)
/// where mounting is not permitted.
class SmallDisk {
 public:
  explicit SmallDisk(const fs::path& dir) : path_(dir / "small") {
    fs::create_directory(path_);
    mounted_ = ::mount("tmpfs", path_.c_str(), "tmpfs", 0, "size=64k") == 0;
    if (!mounted_) reason_ = std::strerror(errno);
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(path_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }
  const std::string& reason() const { return reason_; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  bool mounted_ = false;
  std::string reason_;
};

std::vector<std::string> temporariesIn(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(entry.path().string());
  return found;
}

TEST_F(HostileInput, FullDiskNamesTheFileAndTheReason) {
  SmallDisk disk(dir_.path());
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a small tmpfs to fill (" << disk.reason() << ")";
  writeScene(smallScene());
  const fs::path target = disk.path() / "out.pfm";
  writeText(target, "old\n");
  writeText(disk.path() / "filler", std::string(40 << 10, 'x'));  // 64x64 PFM: 48 KiB
  const RunResult r = runBounded({"render", scenePath().string(), "-o", target.string(), "--backend", "cpu"});
  EXPECT_EQ(r.exitCode, 3) << r.stderrText;
  EXPECT_NE(r.stderrText.find(target.string() + ": write failed: No space left on device"), std::string::npos)
      << r.stderrText;
  EXPECT_EQ(readText(target), "old\n");
  EXPECT_TRUE(temporariesIn(disk.path()).empty());
}

TEST_F(HostileInput, ReferenceOnFullDiskKeepsBothOldImages) {
  SmallDisk disk(dir_.path());
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a small tmpfs to fill (" << disk.reason() << ")";
  writeScene(smallScene());
  const fs::path image = disk.path() / "ref.pfm", error = disk.path() / "ref.stderr.pfm";
  writeText(image, "old image\n");
  writeText(error, "old error\n");
  // Room for one 48 KiB image but not for both.
  const RunResult r =
      runBounded({"reference", scenePath().string(), "-o", image.string(), "--spp", "1", "--threads", "1"});
  EXPECT_EQ(r.exitCode, 3) << r.stderrText;
  EXPECT_NE(r.stderrText.find("write failed: No space left on device"), std::string::npos) << r.stderrText;
  EXPECT_EQ(readText(image), "old image\n");
  EXPECT_EQ(readText(error), "old error\n");
  EXPECT_TRUE(temporariesIn(disk.path()).empty());
}

TEST_F(HostileInput, SigtermDuringReferenceLeavesNoTemporaryAndTheOldImage) {
  json scene = smallScene();
  scene["camera"]["width"] = 256;
  scene["camera"]["height"] = 256;
  writeScene(scene);
  const fs::path image = dir_ / "ref.pfm";
  writeText(image, "old image\n");
  const std::string binary = SSLPV_BINARY;
  const std::vector<std::string> args{binary, "reference", scenePath().string(), "-o", image.string(),
                                      "--spp", "100000", "--threads", "1"};
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  // Long enough for the scene to load and the tracer to start.
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << "status " << status;
  EXPECT_EQ(readText(image), "old image\n");
  EXPECT_TRUE(temporariesIn(dir_.path()).empty());
}

TEST_F(HostileInput, StaleTemporaryOfADeadRunIsRemovedByTheNextWrite) {
  writeScene(smallScene());
  const pid_t dead = ::fork();
  ASSERT_GE(dead, 0);
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const fs::path stale = dir_ / ("out.png.tmp-" + std::to_string(dead) + "-0");
  const fs::path live = dir_ / "out.png.tmp-1-0";  // pid 1 is always alive
  const fs::path other = dir_ / ("other.png.tmp-" + std::to_string(dead) + "-0");
  for (const fs::path& file : {stale, live, other}) writeText(file, "partial");
  const RunResult r = renderBounded();
  EXPECT_EQ(r.exitCode, 0) << r.stderrText;
  EXPECT_FALSE(fs::exists(stale)) << "the dead run's temporary of this output is removed";
  EXPECT_TRUE(fs::exists(live)) << "a live process's temporary is not ours to remove";
  EXPECT_TRUE(fs::exists(other)) << "another output's temporary is left alone";
}

}  // namespace
}  // namespace sslpv::test
