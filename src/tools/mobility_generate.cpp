/// mobility_generate FAMILY [N ...] [--scale S] [--name NAME] [--visuals 0|1] [--shape …] [--order …] >
/// model.urdf Writes a closed-loop URDF (DESIGN.md §2) that closes exactly at the written pose.
#include "mobility_analysis/generators/ClosedLoopUrdf.hpp"
#include "mobility_analysis/generators/FamilyRegistry.hpp"

#include <exception>
#include <iostream>
#include <string>
#include <vector>

namespace {

void printFamilies(std::ostream& out) {
  out << "usage: mobility_generate FAMILY [N ...] [--scale S] [--name NAME] [--visuals 0|1] > model.urdf\n"
         "families (G = Gruebler count, R = redundant equations):\n";
  for (const mobility_analysis::FamilyInfo& info : mobility_analysis::listFamilies()) {
    out << "  " << info.usage << "\n      " << info.summary << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace mobility_analysis;
  try {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.size() == 1 && (args[0] == "--list" || args[0] == "--help" || args[0] == "-h")) {
      printFamilies(std::cout);
      return 0;
    }
    const GeneratorResult<GenerateRequest> request = parseGenerateArguments(args);
    if (const auto* error = std::get_if<GeneratorError>(&request)) {
      std::cerr << "mobility_generate: " << error->what << '\n';
      return 2;
    }
    const GeneratorResult<MechanismDescription> mechanism =
        generateMechanism(std::get<GenerateRequest>(request));
    if (const auto* error = std::get_if<GeneratorError>(&mechanism)) {
      std::cerr << "mobility_generate: " << error->what << '\n';
      return 2;
    }
    UrdfWriterOptions options;
    options.visuals = std::get<GenerateRequest>(request).visuals;
    options.generatorCommand = "mobility_generate";
    for (const std::string& arg : args) {
      options.generatorCommand += ' ' + arg;
    }
    std::ios::sync_with_stdio(false);
    if (const std::optional<GeneratorError> error =
            writeClosedLoopUrdf(std::get<MechanismDescription>(mechanism), std::cout, options)) {
      std::cerr << "mobility_generate: " << error->what << '\n';
      return 2;
    }
    std::cout.flush();
    return std::cout ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "mobility_generate: " << e.what() << '\n';
    return 1;
  }
}
