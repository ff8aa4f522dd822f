#pragma once

#include "mobility_analysis/generators/MechanismDescription.hpp"

#include <optional>
#include <string>
#include <vector>

namespace mobility_analysis {

/// One family the tool can generate.
struct FamilyInfo {
  std::string name;     ///< Command-line name ("sle_spatial").
  int minCounts = 0;    ///< Positional integers required.
  int maxCounts = 0;    ///< Positional integers allowed.
  std::string usage;    ///< "sle_spatial N".
  std::string summary;  ///< One line: what it is and its closed-form DOF / Grübler / redundancy.
};

/// @return Every family, reference mechanisms first.
const std::vector<FamilyInfo>& listFamilies();

/// A parsed `mobility_generate` command line.
struct GenerateRequest {
  std::string family;
  std::vector<int> counts;          ///< Positional integers (N, K, or R C).
  double scale = 1.0;               ///< `--scale`: multiplies every length (1000: millimetres).
  std::optional<std::string> name;  ///< `--name`: URDF robot name.
  bool visuals = true;              ///< `--visuals 0|1`.
  std::optional<std::string> shape;  ///< `--shape straight|zigzag` (chain only).
  std::optional<std::string> order;  ///< `--order root-first|leaf-first` (chain only).
};

/**
 * @brief Parses `FAMILY [N ...] [--option value ...]` (options may also be written with one dash).
 * @param[in] args The arguments after the program name.
 * @return The request, or an error naming the bad argument.
 */
GeneratorResult<GenerateRequest> parseGenerateArguments(const std::vector<std::string>& args);

/**
 * @brief Builds the description a request names, with its expectations.
 * @param[in] request A parsed request.
 * @return The description, or an error (unknown family, count out of range).
 */
GeneratorResult<MechanismDescription> generateMechanism(const GenerateRequest& request);

}  // namespace mobility_analysis
