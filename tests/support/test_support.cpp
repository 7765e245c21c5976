#include "test_support.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace sslpv::test {
namespace fs = std::filesystem;

TempDir::TempDir() {
  std::random_device rd;
  for (int attempt = 0; attempt < 100; ++attempt) {
    fs::path candidate = fs::temp_directory_path() /
                         ("sslpv-test-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    std::error_code ec;
    if (fs::create_directory(candidate, ec)) {
      path_ = candidate;
      return;
    }
  }
  throw std::runtime_error("cannot create a temporary directory");
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

RunResult runProgram(const std::vector<std::string>& command) {
  TempDir capture;
  fs::path outFile = capture / "stdout", errFile = capture / "stderr";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, outFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> argvStorage = command;
  std::vector<char*> argv;
  for (auto& a : argvStorage) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + command.front());
  int status = 0;
  waitpid(pid, &status, 0);
  RunResult result;
  if (WIFEXITED(status)) result.exitCode = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) result.signal = WTERMSIG(status);
  result.stdoutText = readText(outFile);
  result.stderrText = readText(errFile);
  return result;
}

RunResult runSslpv(const std::vector<std::string>& args) {
  std::vector<std::string> command{SSLPV_BINARY};
  command.insert(command.end(), args.begin(), args.end());
  return runProgram(command);
}

fs::path sourceDir() { return SSLPV_SOURCE_DIR; }
fs::path examplesDir() { return sourceDir() / "examples"; }

void expectOneLineError(const RunResult& r, const std::vector<std::string>& needles, int exitCode) {
  SCOPED_TRACE("stderr: " + r.stderrText + "stdout: " + r.stdoutText);
  ::testing::Test::RecordProperty("stderr", r.stderrText);  // the message, for review in the XML report
  EXPECT_EQ(r.signal, 0) << "killed by a signal";
  EXPECT_EQ(r.exitCode, exitCode);
  const std::string& err = r.stderrText;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << "expected exactly one line";
  EXPECT_TRUE(!err.empty() && err.back() == '\n') << "the line should end with a newline";
  EXPECT_EQ(err.rfind("sslpv: error: ", 0), 0u) << "expected the 'sslpv: error: ' prefix";
  for (const auto& needle : needles)
    EXPECT_NE(err.find(needle), std::string::npos) << "the message should name '" << needle << "'";
}

}  // namespace sslpv::test
