#include "mobility_analysis/generators/FamilyRegistry.hpp"

#include "mobility_analysis/generators/ParametricFamilies.hpp"
#include "mobility_analysis/generators/ReferenceMechanisms.hpp"
#include "mobility_analysis/generators/ScalingFamilies.hpp"

#include <charconv>
#include <cmath>
#include <cstdlib>

namespace mobility_analysis {

namespace {

/// Largest count accepted: keeps a typo from exhausting memory (10^6 units ≈ 10^7 joints).
constexpr int kMaxCount = 1000000;

const FamilyInfo* findFamily(const std::string& name) {
  for (const FamilyInfo& info : listFamilies()) {
    if (info.name == name) {
      return &info;
    }
  }
  return nullptr;
}

std::optional<int> parseInt(const std::string& text) {
  int value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size()) {
    return std::nullopt;
  }
  return value;
}

std::optional<double> parseDouble(const std::string& text) {
  if (text.empty()) {
    return std::nullopt;
  }
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

}  // namespace

const std::vector<FamilyInfo>& listFamilies() {
  static const std::vector<FamilyInfo> families = {
      {"four_bar", 0, 0, "four_bar", "Grashof crank-rocker; planar DOF 1 G 1 R 0, spatial DOF 1 G -2 R 3"},
      {"puma560", 0, 0, "puma560", "PUMA 560 open chain; spatial DOF 6 G 6 R 0"},
      {"parallelogram_crank", 0, 0, "parallelogram_crank",
       "parallelogram + third crank pq; planar DOF 1 G 0 R 1"},
      {"three_sliders", 0, 0, "three_sliders",
       "three sliders on an equilateral triangle; planar DOF 1 G 0 R 1"},
      {"rppr", 0, 0, "rppr", "RPPR, slides collinear with the pivots; planar DOF 1 G 1 R 0"},
      {"bennett", 0, 0, "bennett [--scale S]", "Bennett 4R; spatial DOF 1 G -2 R 3"},
      {"sarrus", 0, 0, "sarrus", "Sarrus 6R; spatial DOF 1 G 0 R 1"},
      {"bricard", 0, 0, "bricard", "line-symmetric Bricard 6R; spatial DOF 1 G 0 R 1"},
      {"goldberg", 0, 0, "goldberg", "Goldberg 5R; spatial DOF 1 G -1 R 2"},
      {"rssr", 0, 0, "rssr", "RSSR, rod floating; spatial DOF 2 G 2 R 0"},
      {"flattened_four_bar", 0, 0, "flattened_four_bar",
       "four-bar drawn flat; planar DOF 2 (finite 1) G 1 R 1"},
      {"parallelogram_bifurcation", 0, 0, "parallelogram_bifurcation",
       "parallelogram at its bifurcation; planar DOF 2 (finite 1) G 1 R 1"},
      {"collinear_bars", 0, 0, "collinear_bars",
       "two collinear bars between ground pins; planar DOF 1 (finite 0)"},
      {"stewart_6sps", 0, 0, "stewart_6sps", "Stewart-Gough 6-SPS; spatial DOF 12 (passive 6) G 12 R 0"},
      {"delta_robot", 0, 0, "delta_robot",
       "Delta, ball-jointed parallelogram rods; spatial DOF 9 (passive 6)"},
      {"peaucellier", 0, 0, "peaucellier", "Peaucellier-Lipkin straight-line linkage; planar DOF 1 G 1 R 0"},
      {"sle_mast", 0, 0, "sle_mast", "= sle_planar 4"},
      {"hoberman_ring", 0, 0, "hoberman_ring", "= hoberman 6"},
      {"door", 0, 1, "door [K=3]",
       "door on K coaxial hinges; spatial DOF 1 G 6-5K R 5K-5, planar G 3-2K R 2K-2"},
      {"sle_planar", 1, 1, "sle_planar N", "planar scissor mast, pin + slider base; planar DOF 1 G 1 R 0"},
      {"sle_spatial", 1, 1, "sle_spatial N",
       "scissor mast, pin + slider base, for --mode spatial; spatial DOF 1 G 1-3N R 3N"},
      {"sle_triangular", 1, 1, "sle_triangular N",
       "triangular-prism scissor mast, spherical face pins; spatial DOF 1 G 3-6N R 6N-2"},
      {"hoberman", 1, 1, "hoberman N (N >= 3)", "Hoberman-type ring; planar DOF 1 G -3 R 4"},
      {"sle_deployable", 1, 2, "sle_deployable N [ELEVATION_DEG=10]",
       "SLE mast with passive side cables (taut at 45 deg) and an active base cable; planar DOF 1, deployed 0"},
      {"sle_deployable_folded", 0, 0, "sle_deployable_folded", "= sle_deployable 4 10"},
      {"sle_deployable_partly", 0, 0, "sle_deployable_partly", "= sle_deployable 4 30"},
      {"sle_deployable_deployed", 0, 0, "sle_deployable_deployed", "= sle_deployable 4 45"},
      {"ring_pantograph", 1, 2, "ring_pantograph N (N >= 3) [OPENING_DEG=150]",
       "angulated SLE ring with passive hoop cables (taut at 60 deg) and an active cable; planar DOF 1, deployed 0"},
      {"ring_pantograph_folded", 0, 0, "ring_pantograph_folded", "= ring_pantograph 4 150"},
      {"ring_pantograph_deployed", 0, 0, "ring_pantograph_deployed", "= ring_pantograph 4 60"},
      {"parallelogram_grid", 2, 2, "parallelogram_grid R C",
       "R x C grid of continuous bars; planar DOF 1 G R+C+1-2RC R 2RC-R-C"},
      {"chain", 1, 1, "chain N [--shape straight|zigzag] [--order root-first|leaf-first]",
       "open revolute chain of N links; planar DOF N G N R 0, spatial DOF N G N R 0"},
      {"star", 1, 1, "star N",
       "hub on a ground pin carrying N arms on pins; planar DOF N+1 G N+1 R 0, spatial DOF N+1 G N+1 R 0"},
      {"ring", 1, 1, "ring N (N >= 3)",
       "one loop of N links on a circle, one grounded; planar DOF N-3 G N-3 R 0, spatial DOF N-3 G N-6 R 3"},
      {"bar_lattice", 2, 2, "bar_lattice R C",
       "pin-jointed square bar lattice, R x C cells, bar h_0_0 grounded; planar DOF R+C-1 G R+C-1 R 0 "
       "(Bolker-Crapo)"},
      {"braced_lattice", 2, 2, "braced_lattice R C",
       "bar_lattice with taut cables in both diagonals of every cell; planar DOF 0 G R+C-1-2RC R 2RC-R-C+1"},
      {"truss_mast", 1, 1, "truss_mast N",
       "braced triangular truss mast, N bays, struts as distance constraints, for --mode spatial; "
       "spatial DOF 0 G -3N R 3N (Maxwell s = 3N)"},
      {"ring_pantograph_net", 1, 2, "ring_pantograph_net N (N >= 3) [OPENING_DEG=150]",
       "ring_pantograph with a cable net (hoop + diagonal cables, taut at 60 deg); "
       "planar folded DOF 1 G -3 R 4, deployed DOF 0 G -3-2N R 2N+3"},
  };
  return families;
}

GeneratorResult<GenerateRequest> parseGenerateArguments(const std::vector<std::string>& args) {
  if (args.empty()) {
    return GeneratorError{"missing FAMILY (try --list)"};
  }
  GenerateRequest request;
  request.family = args.front();
  const FamilyInfo* info = findFamily(request.family);
  if (info == nullptr) {
    return GeneratorError{"unknown family '" + request.family + "' (try --list)"};
  }
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (!arg.empty() && arg[0] == '-' && !parseInt(arg)) {
      const std::string key = arg.substr(arg.rfind('-') + 1);
      if (i + 1 >= args.size()) {
        return GeneratorError{"option '" + arg + "' needs a value"};
      }
      const std::string& value = args[++i];
      if (key == "scale") {
        const std::optional<double> scale = parseDouble(value);
        if (!scale || *scale <= 0.0) {
          return GeneratorError{"--scale: expected a positive number, got '" + value + "'"};
        }
        request.scale = *scale;
      } else if (key == "name") {
        if (value.empty() || value.find_first_of("\"<>&' ") != std::string::npos) {
          return GeneratorError{"--name: '" + value + "' is not a plain robot name"};
        }
        request.name = value;
      } else if (key == "visuals") {
        if (value != "0" && value != "1") {
          return GeneratorError{"--visuals: expected 0 or 1, got '" + value + "'"};
        }
        request.visuals = value == "1";
      } else if (key == "shape") {
        if (value != "straight" && value != "zigzag") {
          return GeneratorError{"--shape: expected straight or zigzag, got '" + value + "'"};
        }
        request.shape = value;
      } else if (key == "order") {
        if (value != "root-first" && value != "leaf-first") {
          return GeneratorError{"--order: expected root-first or leaf-first, got '" + value + "'"};
        }
        request.order = value;
      } else {
        return GeneratorError{"unknown option '" + arg +
                              "' (options: --scale, --name, --visuals; chain: --shape, --order)"};
      }
      continue;
    }
    const std::optional<int> count = parseInt(arg);
    if (!count) {
      return GeneratorError{request.family + ": expected an integer, got '" + arg + "'"};
    }
    request.counts.push_back(*count);
  }
  if ((request.shape || request.order) && request.family != "chain") {
    return GeneratorError{request.family + ": --shape and --order are options of chain only"};
  }
  const int numCounts = static_cast<int>(request.counts.size());
  if (numCounts < info->minCounts || numCounts > info->maxCounts) {
    return GeneratorError{request.family + ": expected " + info->usage + ", got " +
                          std::to_string(numCounts) + " count(s)"};
  }
  for (int count : request.counts) {
    if (count < 1 || count > kMaxCount) {
      return GeneratorError{request.family + ": count " + std::to_string(count) + " out of range 1.." +
                            std::to_string(kMaxCount)};
    }
  }
  return request;
}

GeneratorResult<MechanismDescription> generateMechanism(const GenerateRequest& request) {
  const std::string& family = request.family;
  const std::vector<int>& n = request.counts;
  MechanismDescription mechanism;
  if (family == "four_bar") {
    mechanism = makeFourBar();
  } else if (family == "puma560") {
    mechanism = makePuma560();
  } else if (family == "parallelogram_crank") {
    mechanism = makeParallelogramCrank();
  } else if (family == "three_sliders") {
    mechanism = makeThreeSliders();
  } else if (family == "rppr") {
    mechanism = makeRppr();
  } else if (family == "bennett") {
    mechanism = makeBennett();
  } else if (family == "sarrus") {
    mechanism = makeSarrus();
  } else if (family == "bricard") {
    mechanism = makeBricard();
  } else if (family == "goldberg") {
    mechanism = makeGoldberg();
  } else if (family == "rssr") {
    mechanism = makeRssr();
  } else if (family == "flattened_four_bar") {
    mechanism = makeFlattenedFourBar();
  } else if (family == "parallelogram_bifurcation") {
    mechanism = makeParallelogramBifurcation();
  } else if (family == "collinear_bars") {
    mechanism = makeCollinearBars();
  } else if (family == "stewart_6sps") {
    mechanism = makeStewart6Sps();
  } else if (family == "delta_robot") {
    mechanism = makeDeltaRobot();
  } else if (family == "peaucellier") {
    mechanism = makePeaucellier();
  } else if (family == "sle_mast") {
    mechanism = makeSlePlanarMast(4);
    mechanism.name = "sle_mast";
  } else if (family == "hoberman_ring") {
    mechanism = makeHobermanRing(6);
    mechanism.name = "hoberman_ring";
  } else if (family == "door") {
    mechanism = makeDoor(n.empty() ? 3 : n[0]);
  } else if (family == "sle_planar") {
    mechanism = makeSlePlanarMast(n.at(0));
  } else if (family == "sle_spatial") {
    mechanism = makeSleSpatialMast(n.at(0));
  } else if (family == "sle_triangular") {
    mechanism = makeSleTriangularMast(n.at(0));
  } else if (family == "hoberman") {
    if (n.at(0) < 3) {
      return GeneratorError{
          "hoberman: N must be at least 3 (a ring of fewer angulated units folds flat), got " +
          std::to_string(n[0])};
    }
    mechanism = makeHobermanRing(n[0]);
  } else if (family == "sle_deployable") {
    if (n.size() > 1 && n[1] > 45) {
      return GeneratorError{"sle_deployable: ELEVATION_DEG must be in 1..45 (the passive cables stop it at 45), got " +
                            std::to_string(n[1])};
    }
    mechanism = makeSleDeployableMast(n.at(0), n.size() > 1 ? n[1] : 10.0);
  } else if (family == "sle_deployable_folded" || family == "sle_deployable_partly" ||
             family == "sle_deployable_deployed") {
    const double elevation = family == "sle_deployable_folded" ? 10.0 : family == "sle_deployable_partly" ? 30.0 : 45.0;
    mechanism = makeSleDeployableMast(4, elevation);
    mechanism.name = family;
  } else if (family == "ring_pantograph") {
    if (n.at(0) < 3 || (n.size() > 1 && (n[1] < 60 || n[1] > 179))) {
      return GeneratorError{"ring_pantograph: N must be at least 3 and OPENING_DEG in 60..179 (it deploys to 60)"};
    }
    mechanism = makeRingPantograph(n[0], n.size() > 1 ? n[1] : 150.0);
  } else if (family == "ring_pantograph_folded" || family == "ring_pantograph_deployed") {
    mechanism = makeRingPantograph(4, family == "ring_pantograph_folded" ? 150.0 : 60.0);
    mechanism.name = family;
  } else if (family == "parallelogram_grid") {
    mechanism = makeParallelogramGrid(n.at(0), n.at(1));
  } else if (family == "chain") {
    mechanism = makeChain(
        n.at(0), request.shape.value_or("straight") == "zigzag" ? ChainShape::Zigzag : ChainShape::Straight,
        request.order.value_or("root-first") == "leaf-first" ? ChainOrder::LeafFirst : ChainOrder::RootFirst);
  } else if (family == "star") {
    mechanism = makeStar(n.at(0));
  } else if (family == "ring") {
    if (n.at(0) < 3) {
      return GeneratorError{"ring: N must be at least 3 (a loop needs three links), got " +
                            std::to_string(n[0])};
    }
    mechanism = makeRing(n[0]);
  } else if (family == "bar_lattice" || family == "braced_lattice") {
    mechanism = makeBarLattice(n.at(0), n.at(1), family == "braced_lattice");
  } else if (family == "truss_mast") {
    mechanism = makeTrussMast(n.at(0));
  } else if (family == "ring_pantograph_net") {
    if (n.at(0) < 3 || (n.size() > 1 && (n[1] < 60 || n[1] > 179))) {
      return GeneratorError{
          "ring_pantograph_net: N must be at least 3 and OPENING_DEG in 60..179 (it deploys to 60)"};
    }
    mechanism = makeRingPantographNet(n[0], n.size() > 1 ? n[1] : 150.0);
  } else {
    return GeneratorError{"unknown family '" + family + "'"};
  }
  if (request.scale != 1.0) {
    scaleMechanism(mechanism, request.scale);
    mechanism.comment += "\nAll lengths multiplied by " + std::to_string(request.scale) + " (--scale).";
  }
  if (request.name) {
    mechanism.name = *request.name;
  }
  return mechanism;
}

}  // namespace mobility_analysis
