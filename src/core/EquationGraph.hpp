#pragma once

// Private to src/core: the local stress searches (SelfStressBasis.cpp, ContractEchelon.cpp) grow balls of
// links through it.

#include <vector>

#include "mobility_analysis/Mechanism.hpp"
#include "mobility_analysis/NaturalCoordinates.hpp"

namespace mobility_analysis {
namespace core_detail {

/// Which equations belong to which link and connection, and which connections couple which links.
struct EquationGraph {
  std::vector<std::vector<int>> linkRows;   ///< Rigid-link and boundary rows of each link.
  std::vector<std::vector<int>> jointRows;  ///< Rows of each connection.
  std::vector<std::vector<int>> incident;   ///< Connections with equations at each link, each once.

  EquationGraph(const Mechanism& mechanism, const CoordinateModel& model)
      : linkRows(mechanism.links.size()),
        jointRows(mechanism.joints.size()),
        incident(mechanism.links.size()) {
    for (int r = 0; r < model.numConstraints(); ++r) {
      const ConstraintEquation& eq = model.equations[r];
      (eq.source == EquationSource::Joint ? jointRows : linkRows)[eq.element].push_back(r);
    }
    for (size_t j = 0; j < mechanism.joints.size(); ++j) {
      if (jointRows[j].empty())
        continue;
      incident[mechanism.joints[j].link1].push_back(static_cast<int>(j));
      // A coupling can join a link to itself (its follower's and leader's child).
      if (mechanism.joints[j].link2 != mechanism.joints[j].link1)
        incident[mechanism.joints[j].link2].push_back(static_cast<int>(j));
    }
  }
};

}  // namespace core_detail
}  // namespace mobility_analysis
