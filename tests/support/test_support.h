#pragma once
// Helpers shared by the test binaries: a private temporary directory per test (tests
// run in parallel under ctest -j) and running the sslpv binary as a user would.
#include <filesystem>
#include <string>
#include <vector>

namespace sslpv::test {

/// A fresh directory, removed when the object goes away.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

void writeText(const std::filesystem::path& file, const std::string& text);
std::string readText(const std::filesystem::path& file);

struct RunResult {
  int exitCode = -1;       ///< -1 when killed by a signal
  int signal = 0;          ///< the signal number when killed
  std::string stdoutText;
  std::string stderrText;
};

/// Runs `command` (argv[0] searched in PATH, no shell), capturing its output.
RunResult runProgram(const std::vector<std::string>& command);

/// Runs the built sslpv binary with `args` (no shell), capturing its output.
RunResult runSslpv(const std::vector<std::string>& args);

/// The CLI's failure contract on stderr: not killed by a signal, exit code `exitCode`,
/// exactly one line starting "sslpv: error: " that contains every needle (gtest
/// expectations; the caller checks its own output files).
void expectOneLineError(const RunResult& r, const std::vector<std::string>& needles, int exitCode = 2);

/// The repository root and the example folder.
std::filesystem::path sourceDir();
std::filesystem::path examplesDir();

}  // namespace sslpv::test
