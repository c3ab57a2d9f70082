#pragma once
// An empty scratch folder of the test run (removed and made again), for tests that write files.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace mfsi::test {

inline std::string freshDir(const std::string& tag) {
  const std::string dir = ::testing::TempDir() + "/" + tag;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace mfsi::test
