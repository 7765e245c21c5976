// The command line's wait notice: silent for short waits and off a terminal, a ticking
// line for long ones on a terminal, erased when the wait ends.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "apps/cli_output.h"

namespace {
using namespace sslpv;
using namespace std::chrono_literals;

/// What `notice` wrote to its stream while `wait` passed.
template <typename Wait>
std::string written(std::chrono::milliseconds delay, bool terminal, Wait wait) {
  std::FILE* out = std::tmpfile();
  {
    WaitNotice notice("render: preparing", delay, terminal, out);
    wait();
  }
  std::fflush(out);
  std::rewind(out);
  std::string text;
  for (int c = std::fgetc(out); c != EOF; c = std::fgetc(out)) text.push_back(char(c));
  std::fclose(out);
  return text;
}

TEST(WaitNotice, ALongWaitOnATerminalTicksAndIsErased) {
  const std::string text = written(50ms, true, [] { std::this_thread::sleep_for(700ms); });
  // Ticks every 250 ms from 50 ms: at least two lines, each redrawn from the line start.
  EXPECT_GE(std::count(text.begin(), text.end(), '\r'), 3) << text;
  EXPECT_NE(text.find("render: preparing ... 0."), std::string::npos) << text;
  // The last thing written blanks the line and returns to its start.
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\r');
  const std::size_t lastLine = text.rfind('\r', text.size() - 2);
  ASSERT_NE(lastLine, std::string::npos);
  EXPECT_EQ(text.substr(lastLine + 1, text.size() - lastLine - 2).find_first_not_of(' '), std::string::npos) << text;
}

TEST(WaitNotice, AShortWaitOrNoTerminalWritesNothing) {
  EXPECT_EQ(written(1s, true, [] { std::this_thread::sleep_for(20ms); }), "");
  EXPECT_EQ(written(10ms, false, [] { std::this_thread::sleep_for(100ms); }), "");
}

}  // namespace
