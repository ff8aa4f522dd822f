#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace mobility_analysis {

/// The whole file as it is on disk (bytes unchanged); empty when it cannot be read. For tests.
inline std::string readTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace mobility_analysis
