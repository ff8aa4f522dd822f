/// mobility_benchmark --method full|finite|literal|dense FILE.urdf [--mode auto|planar|spatial] [--budget SECONDS]
///
/// Measures one method on one model in this process and prints one line:
///   method=<m> file=<f> coordinates=<n> equations=<m> dof=<d> redundant=<r> seconds=<t> peak_mb=<p> status=<s>
/// full:    our whole report, end to end as `mobility_report --json` does it: read and load the URDF, assemble,
///          Jacobian, self-stress basis, ordered redundancy, loops and redundant links, JSON text; the line adds
///          load_seconds, analysis_seconds and json_bytes;
/// literal: the lecture's algorithm, the nullity of the first k rows after each equation (ColPivHouseholderQR);
/// dense:   one dense rank-revealing decomposition (ColPivHouseholderQR) of the same Jacobian;
/// finite:  the finite-mobility test (second-order test, step-and-project) and the passive-freedom search, timed
///          next to the plain first-order core they follow (Jacobian, self-stress basis, ordered rank); the line
///          has finite_dof, passive_dof, plain_seconds, finite_seconds, passive_seconds and ratio = all / plain.
/// spqr:    one SuiteSparse SPQR rank-revealing sparse QR (Eigen::SPQR, SPQR's default tolerance) of the same
///          row-normalised Jacobian: the floor for any sparse rank answer (counts only); built when SuiteSparse
///          is found;
/// parse:   the bare XML parse of the file as the URDF reader does it (read into one buffer, pugixml in place),
///          nothing else: the floor of loading; tinyxml2_seconds is one tinyxml2 LoadFile of it, for comparison;
/// load:    loading alone: read the file, parse it and build the checked mechanism (what full spends before
///          the analysis), with its processor seconds;
/// slvs:    SolveSpace's solver (libslvs) on the planar bar-and-pin models it can express (SolveSpacePeer.hpp):
///          one Slvs_Solve, its dof; built only when libslvs is found (status=unsupported otherwise);
/// orders:  the fill and time of the self-stress basis's row elimination in the sweep's order, in SuiteSparse
///          AMD's order of the link graph and in contract order (EliminationOrders.hpp), one line each; built
///          when SuiteSparse AMD is found.
/// Peak memory is the process's maximum resident set (getrusage), so run one method per process.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <iostream>
#include <optional>
#include <streambuf>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <sys/resource.h>
#include <pugixml.hpp>
#include <tinyxml2.h>
#ifdef MA_HAVE_SPQR
#include <Eigen/CholmodSupport>
#include <SuiteSparseQR.hpp>
#endif
#ifdef MA_HAVE_SLVS
#include "SolveSpacePeer.hpp"
#endif
#ifdef MA_HAVE_AMD
#include "EliminationOrders.hpp"
#endif

#include "HugePageHeap.hpp"
#include "mobility_analysis/analysis/FiniteMobility.hpp"
#include "mobility_analysis/analysis/PassiveFreedoms.hpp"
#include "mobility_analysis/io/ReadMechanism.hpp"
#include "mobility_analysis/mobility_analysis.hpp"

using namespace mobility_analysis;

namespace {

/// A stream buffer that keeps nothing and counts what it was given.
struct ByteCounter : std::streambuf {
  size_t bytes = 0;
  std::streamsize xsputn(const char*, std::streamsize count) override {
    bytes += static_cast<size_t>(count);
    return count;
  }
  int_type overflow(int_type c) override {
    if (!traits_type::eq_int_type(c, traits_type::eof()))
      ++bytes;
    return traits_type::not_eof(c);
  }
};

double peakMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

/// Processor time of this process so far [s].
double cpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

constexpr const char* kUsage =
    "usage: mobility_benchmark --method full|finite|literal|dense|spqr|parse|load|slvs|orders FILE.urdf [--mode M] [--budget S] [--orientation auto|J|JT] [--one-thread]";

/// The mechanism assembled from its tree pose and the constraint Jacobian there: what the baselines (spqr,
/// dense, literal, orders) are handed, built outside their timed regions.
struct JacobianAtTreePose {
  AssembledMechanism assembled;
  SparseJacobian J;
};

Result<JacobianAtTreePose> jacobianAtTreePose(const Mechanism& mechanism, AnalysisMode mode) {
  Result<AssembledMechanism> assembled = assembleMechanism(mechanism, computeTreePoses(mechanism, {}), mode);
  if (!isOk(assembled)) return diagnosticOf(assembled);
  JacobianAtTreePose at{valueOf(std::move(assembled)), {}};
  at.J = computeConstraintJacobian(at.assembled.model, at.assembled.q);
  return at;
}

int fail(const std::string& line) {
  std::cerr << line << std::endl;
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string method = "full", file, modeText = "auto";
  double budget = 60.0;
  std::string orientation = "auto";  // spqr: factor J, J^T, or (auto) whichever is wide
  bool oneThread = false;            // full: no second thread (AnalysisOptions::sideThreads, toJson)
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if ((arg == "--method" || arg == "--mode" || arg == "--budget" || arg == "--orientation") && i + 1 < argc) {
      const std::string value = argv[++i];
      if (arg == "--method") method = value;
      if (arg == "--mode") modeText = value;
      if (arg == "--budget") budget = std::stod(value);
      if (arg == "--orientation") orientation = value;
    } else if (arg == "--one-thread") {
      oneThread = true;
    } else if (file.empty() && arg[0] != '-') {
      file = arg;
    } else {
      return fail(kUsage);
    }
  }
  if (file.empty() || (method != "full" && method != "finite" && method != "literal" && method != "dense" &&
                       method != "spqr" && method != "parse" && method != "load" && method != "slvs" &&
                       method != "orders")) {
    return fail(kUsage);
  }
  const Result<AnalysisMode> mode = parseAnalysisMode(modeText);
  if (!isOk(mode)) return fail(diagnosticOf(mode).toString());
  if (method == "parse") {
    // The floor of loading: the URDF reader's own parse (io/UrdfReader.cpp: the file read into one buffer,
    // pugixml parsing it in place with the reader's options), then, as a second figure, one tinyxml2 parse of
    // the file (the reader's parser until issue 13's load work). peak_mb is taken after the first only.
    const auto parseStart = std::chrono::steady_clock::now();
    const double parseCpuStart = cpuSeconds();
    double parseSeconds = 0.0, parseCpuSeconds = 0.0, parseMegabytes = 0.0;
    {
      std::string text;
      std::FILE* in = std::fopen(file.c_str(), "rb");
      if (in == nullptr) return fail(file + ": cannot open the file");
      std::fseek(in, 0, SEEK_END);
      text.resize(static_cast<size_t>(std::max(0L, std::ftell(in))));
      std::rewind(in);
      text.resize(std::fread(&text[0], 1, text.size(), in));
      std::fclose(in);
      pugi::xml_document document;
      const pugi::xml_parse_result parsed = document.load_buffer_inplace(
          &text[0], text.size(), pugi::parse_cdata | pugi::parse_escapes | pugi::parse_eol | pugi::parse_fragment);
      parseSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - parseStart).count();
      parseCpuSeconds = cpuSeconds() - parseCpuStart;
      parseMegabytes = peakMegabytes();
      if (!parsed) return fail(file + ": " + parsed.description());
    }
    const auto tinyStart = std::chrono::steady_clock::now();
    tinyxml2::XMLDocument document;
    const tinyxml2::XMLError error = document.LoadFile(file.c_str());
    const double tinySeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tinyStart).count();
    if (error != tinyxml2::XML_SUCCESS) return fail(file + ": " + document.ErrorStr());
    std::printf("method=parse file=%s coordinates=-1 equations=-1 dof=-1 redundant=-1 seconds=%.4f cpu_seconds=%.4f "
                "tinyxml2_seconds=%.4f peak_mb=%.1f status=ok\n",
                file.c_str(), parseSeconds, parseCpuSeconds, tinySeconds, parseMegabytes);
    return 0;
  }
  // The clock starts before the file is read: "full" is what `mobility_report --json` does, end to end.
  const auto start = std::chrono::steady_clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  // Read as mobility_report reads it (the front door of the readers).
  ReadOptions readOptions;
  readOptions.sideThread = !oneThread;
  const Result<Mechanism> mechanism = readMechanism(file, readOptions);
  if (!isOk(mechanism)) return fail(diagnosticOf(mechanism).toString());
  const double loadSeconds = seconds();
  const double loadCpuSeconds = cpuSeconds();

  int n = 0, m = 0, dof = -1, redundant = -1;
  std::string status = "ok";
  if (method == "load") {
    // Loading alone (read the file, parse it, build and check the mechanism), next to parse: the reader's cost.
    std::printf("method=load file=%s coordinates=-1 equations=-1 dof=-1 redundant=-1 seconds=%.4f cpu_seconds=%.4f "
                "links=%zu joints=%zu peak_mb=%.1f status=ok\n",
                file.c_str(), loadSeconds, loadCpuSeconds, valueOf(mechanism).links.size(),
                valueOf(mechanism).joints.size(), peakMegabytes());
    return 0;
  }
  if (method == "full") {
    AnalysisOptions options;
    options.mode = valueOf(mode);
    options.sideThreads = !oneThread;
    // Where the analysis goes: the processor seconds from each phase the analysis announces to the next (on
    // stderr; processor time, not wall clock, so that figures taken on a shared machine compare). The process'
    // time: on a large model the work of the second thread (finds made ahead, the passive-freedom search, the
    // self-stress report, the second half of the JSON) counts in the phase the main thread is in meanwhile.
    // Beside it, the wall-clock seconds of each phase (what the second thread saves shows there).
    struct Phase {
      std::string name;
      double cpu, wall;
    };
    std::vector<Phase> phases;
    options.progress = [&](const std::string& phase, double) {
      if (phases.empty() || phases.back().name != phase) phases.push_back({phase, cpuSeconds(), seconds()});
    };
    const Result<MobilityAnalysis> analysis = analyzeMechanism(valueOf(mechanism), options);
    if (!isOk(analysis)) return fail(diagnosticOf(analysis).toString());
    const MobilityReport& report = valueOf(analysis).report;
    const double analysisSeconds = seconds() - loadSeconds;
    const Phase json{"json", cpuSeconds(), seconds()};
    // Written as the CLI writes it (writeJson to a stream), into a sink that only counts the bytes: what the
    // text costs to make, not what the terminal or disk costs to take it.
    ByteCounter counter;
    std::ostream sink(&counter);
    if (const std::optional<Diagnostic> refused = writeJson(report, sink, !oneThread))
      return fail(refused->toString());
    phases.push_back(json);
    phases.push_back({"", cpuSeconds(), seconds()});
    std::fprintf(stderr, "cpu seconds: load %.3f", loadCpuSeconds);
    for (size_t p = 0; p + 1 < phases.size(); ++p)
      std::fprintf(stderr, ", %s %.3f", phases[p].name.c_str(), phases[p + 1].cpu - phases[p].cpu);
    std::fprintf(stderr, "\nwall seconds: load %.3f", loadSeconds);
    for (size_t p = 0; p + 1 < phases.size(); ++p)
      std::fprintf(stderr, ", %s %.3f", phases[p].name.c_str(), phases[p + 1].wall - phases[p].wall);
    std::fprintf(stderr, "\n");
    n = report.numCoordinates;
    m = report.numConstraints;
    dof = report.dof;
    redundant = report.numRedundant;
    // heap: the allocator and its options (HugePageHeap.hpp), the same for every method of this program.
    std::printf(
        "method=full file=%s coordinates=%d equations=%d dof=%d redundant=%d seconds=%.4f load_seconds=%.4f "
        "analysis_seconds=%.4f json_bytes=%zu peak_mb=%.1f heap=%s status=ok\n",
        file.c_str(), n, m, dof, redundant, seconds(), loadSeconds, analysisSeconds, counter.bytes,
        peakMegabytes(), heapDescription().c_str());
    return 0;
  } else if (method == "finite") {
    // The finite-mobility and passive-freedom tests timed next to the plain first-order analysis they follow
    // (Jacobian, self-stress basis, ordered rank), all on the assembled pose.
    const Result<AssembledMechanism> assembled =
        assembleMechanism(valueOf(mechanism), computeTreePoses(valueOf(mechanism), {}), valueOf(mode));
    if (!isOk(assembled)) return fail(diagnosticOf(assembled).toString());
    const AssembledMechanism& a = valueOf(assembled);
    auto since = [](auto t) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count(); };
    const auto plainStart = std::chrono::steady_clock::now();
    const SparseJacobian J = computeConstraintJacobian(a.model, a.q);
    const SelfStressBasis basis = computeSelfStressBasis(valueOf(mechanism), a.model, J, tolerances::kRank);
    const std::optional<OrderedRank> ranks = computeOrderedRankFromStresses(basis, tolerances::kRank);
    const OrderedRank order = ranks ? *ranks : computeOrderedRank(J, tolerances::kRank, false);
    const double plainSeconds = since(plainStart);
    const auto finiteStart = std::chrono::steady_clock::now();
    const FiniteMobility finite = analyzeFiniteMobility(a.model, a.q, J, basis, order, tolerances::kRank);
    const double finiteSeconds = since(finiteStart);
    const auto passiveStart = std::chrono::steady_clock::now();
    const PassiveFreedoms passive = findPassiveFreedoms(valueOf(mechanism), a.model, a.q, J);
    const double passiveSeconds = since(passiveStart);
    std::printf(
        "method=finite file=%s coordinates=%d equations=%d dof=%d finite_dof=%d passive_dof=%d plain_seconds=%.4f "
        "finite_seconds=%.4f passive_seconds=%.4f ratio=%.2f stepped=%d searched_groups=%d rigid_by_ends=%d peak_mb=%.1f "
        "status=ok\n",
        file.c_str(), a.model.numCoordinates(), a.model.numConstraints(), order.dof(), finite.finiteDof, passive.dof,
        plainSeconds, finiteSeconds, passiveSeconds, (plainSeconds + finiteSeconds + passiveSeconds) / plainSeconds,
        finite.steppedAndProjected ? 1 : 0, passive.groupsSearched, passive.groupsRigidByEnds, peakMegabytes());
    return 0;
  } else if (method == "slvs") {
#ifdef MA_HAVE_SLVS
    const bench::SolveSpaceResult slvs =
        bench::solveWithSolveSpace(valueOf(mechanism), computeTreePoses(valueOf(mechanism), {}), false);
    std::printf("method=slvs file=%s coordinates=%d equations=%d dof=%d redundant=-1 seconds=%.4f peak_mb=%.1f status=%s\n",
                file.c_str(), slvs.parameters, slvs.constraints, slvs.status == "ok" ? slvs.dof : -1,
                slvs.solveSeconds, peakMegabytes(), slvs.status.substr(0, slvs.status.find(':')).c_str());
    if (slvs.status.rfind("unsupported", 0) == 0) std::cerr << slvs.status << std::endl;
#else
    std::printf("method=slvs file=%s coordinates=-1 equations=-1 dof=-1 redundant=-1 seconds=0 peak_mb=%.1f "
                "status=unsupported\n", file.c_str(), peakMegabytes());
    std::cerr << "mobility_benchmark was built without libslvs (libslvs1-dev)" << std::endl;
#endif
    return 0;
  } else if (method == "orders") {
#ifdef MA_HAVE_AMD
    // Issue 13, item 2: the sweep's elimination order against a fill-reducing order of the link graph.
    const Result<JacobianAtTreePose> at = jacobianAtTreePose(valueOf(mechanism), valueOf(mode));
    if (!isOk(at)) return fail(diagnosticOf(at).toString());
    return printEliminationOrders(valueOf(mechanism), valueOf(at).assembled.model, valueOf(at).J, file);
#else
    status = "unsupported";
    std::cerr << "mobility_benchmark was built without SuiteSparse AMD" << std::endl;
#endif
  } else if (method == "spqr") {
    // One sparse rank-revealing QR of the same Jacobian the full report ranks, built and row-normalised outside
    // the timed region (as for dense): the lower bound for any sparse rank answer.
    Result<JacobianAtTreePose> at = jacobianAtTreePose(valueOf(mechanism), valueOf(mode));
    if (!isOk(at)) return fail(diagnosticOf(at).toString());
    SparseJacobian J = valueOf(std::move(at)).J;
    n = static_cast<int>(J.cols());
    m = static_cast<int>(J.rows());
#ifdef MA_HAVE_SPQR
    Eigen::SparseMatrix<double, Eigen::RowMajor> rows(J);
    for (int r = 0; r < m; ++r) {
      double norm = 0;
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, r); it; ++it) norm += it.value() * it.value();
      norm = std::sqrt(norm);
      if (norm == 0) continue;
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, r); it; ++it) it.valueRef() /= norm;
    }
    // SPQR wants 64-bit indices. Orientation: the rank is the same; SPQR is much faster on the wide one (rows <=
    // columns) here: 100x100 grid J 10.6 s, J^T 0.56 s; 10^5-link chain J 0.13 s, J^T 0.37 s. auto picks it.
    const bool transpose = orientation == "JT" || (orientation == "auto" && m > n);
    Eigen::SparseMatrix<double, Eigen::ColMajor, SuiteSparse_long> A;
    if (transpose) A = rows.transpose(); else A = rows;
    A.makeCompressed();
    cholmod_common common;
    cholmod_l_start(&common);
    cholmod_sparse view = Eigen::viewAsCholmod(A);
    cholmod_sparse* R = nullptr;
    SuiteSparse_long* E = nullptr;
    const auto timed = std::chrono::steady_clock::now();
    // [R, E] = qr(A) without Q (the Householder vectors are discarded): the rank and nothing else.
    const SuiteSparse_long rank =
        SuiteSparseQR<double>(SPQR_ORDERING_DEFAULT, SPQR_DEFAULT_TOL, 0, &view, &R, &E, &common);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - timed).count();
    if (rank < 0 || common.status != CHOLMOD_OK) {
      status = "failed";
    } else {
      dof = n - static_cast<int>(rank);
      redundant = m - static_cast<int>(rank);
    }
    cholmod_l_free_sparse(&R, &common);
    if (E != nullptr) cholmod_l_free(A.cols(), sizeof(SuiteSparse_long), E, &common);
    cholmod_l_finish(&common);
    std::printf("method=spqr file=%s coordinates=%d equations=%d dof=%d redundant=%d seconds=%.4f orientation=%s peak_mb=%.1f status=%s\n",
                file.c_str(), n, m, dof, redundant, elapsed, transpose ? "JT" : "J", peakMegabytes(), status.c_str());
    return 0;
#else
    status = "unsupported";
    std::cerr << "mobility_benchmark was built without SuiteSparse SPQR" << std::endl;
#endif
  } else {
    // The same Jacobian the full report uses, built outside the timed region for the baselines.
    const Result<JacobianAtTreePose> at = jacobianAtTreePose(valueOf(mechanism), valueOf(mode));
    if (!isOk(at)) return fail(diagnosticOf(at).toString());
    const SparseJacobian& J = valueOf(at).J;
    n = static_cast<int>(J.cols());
    m = static_cast<int>(J.rows());
    const double denseBytes = 8.0 * n * m;
    if (denseBytes > 8e9) {
      status = "skipped_memory";
    } else {
      Eigen::MatrixXd dense = Eigen::MatrixXd(J);
      for (int r = 0; r < m; ++r) dense.row(r) /= dense.row(r).norm();
      const auto timed = std::chrono::steady_clock::now();
      if (method == "dense") {
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(dense);
        qr.setThreshold(tolerances::kRank);
        dof = n - static_cast<int>(qr.rank());
        redundant = m - static_cast<int>(qr.rank());
      } else {
        // Literal: one decomposition per added equation; stop when the budget is spent.
        int rank = 0;
        for (int r = 0; r < m; ++r) {
          Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(dense.topRows(r + 1));
          qr.setThreshold(tolerances::kRank);
          rank = static_cast<int>(qr.rank());
          if (std::chrono::duration<double>(std::chrono::steady_clock::now() - timed).count() > budget) {
            status = "over_budget_at_row_" + std::to_string(r);
            break;
          }
        }
        if (status == "ok") {
          dof = n - rank;
          redundant = m - rank;
        }
      }
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - timed).count();
      std::printf("method=%s file=%s coordinates=%d equations=%d dof=%d redundant=%d seconds=%.4f peak_mb=%.1f status=%s\n",
                  method.c_str(), file.c_str(), n, m, dof, redundant, elapsed, peakMegabytes(), status.c_str());
      return 0;
    }
  }
  std::printf("method=%s file=%s coordinates=%d equations=%d dof=%d redundant=%d seconds=%.4f peak_mb=%.1f status=%s\n",
              method.c_str(), file.c_str(), n, m, dof, redundant, seconds(), peakMegabytes(), status.c_str());
  return 0;
}
