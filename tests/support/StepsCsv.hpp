#pragma once
// A run's steps.csv read back as columns (header names -> values per step).
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

}  // namespace mfsi::test
