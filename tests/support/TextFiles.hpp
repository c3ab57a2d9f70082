#pragma once
// A text file read whole (a run's CSV, JSON or log), for tests that check what a run wrote.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

namespace mfsi::test {

/// The file's text; a file that cannot be opened fails the test (non-fatally) and reads as "".
inline std::string readFile(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot open " << path;
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace mfsi::test
