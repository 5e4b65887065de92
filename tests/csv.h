#pragma once
// A CSV file (metrics.csv and kin) as rows of cells, the header first.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace segue {

inline std::vector<std::vector<std::string>> csv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) row.push_back(cell);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace segue
