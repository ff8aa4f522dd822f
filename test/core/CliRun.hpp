#pragma once

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/wait.h>

namespace mobility_analysis {

/// What one run of the CLI gave: exit status, stdout, stderr.
struct CliRun {
  int status;
  std::string out, err;
};

/// Runs `mobility_report ARGUMENTS` as a user would (MA_REPORT_EXE), stdout and stderr kept apart.
inline CliRun runReport(const std::string& arguments) {
  const std::string errFile = ::testing::TempDir() + "mobility_report_stderr_" +
                              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".txt";
  const std::string command = std::string(MA_REPORT_EXE) + " " + arguments + " 2>" + errFile;
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.out.append(buffer.data(), n);
  run.status = WEXITSTATUS(pclose(pipe));
  std::ifstream err(errFile);
  std::stringstream text;
  text << err.rdbuf();
  run.err = text.str();
  return run;
}

}  // namespace mobility_analysis
