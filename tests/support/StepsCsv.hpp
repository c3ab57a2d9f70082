#pragma once
// A run's steps.csv read back as columns (header names -> values per step), or as text without its
// wall-time column (what two runs that took different times must agree on, exactly).
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace mfsi::test {

inline std::map<std::string, std::vector<double>> readSteps(const std::string& file) {
  std::ifstream in(file);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::istringstream h(line); std::getline(h, cell, ',');) names.push_back(cell);
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    for (std::size_t k = 0; k < names.size() && std::getline(s, cell, ','); ++k) cols[names[k]].push_back(std::stod(cell));
  }
  return cols;
}

/// The file's text without its third column (wall_s), row by row, each cell followed by a comma.
inline std::string stepsWithoutWallTime(const std::string& file) {
  std::ifstream in(file);
  std::string line, out;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    int i = 0;
    for (std::string c; std::getline(ls, c, ','); ++i)
      if (i != 2) out += c + ",";
    out += "\n";
  }
  return out;
}

}  // namespace mfsi::test
