#include "mobility_analysis/ConstraintJacobian.hpp"

#include <algorithm>
#include <vector>

#include "mobility_analysis/coordinates/EquationForms.hpp"

#include "SideTask.hpp"

namespace mobility_analysis {

// Each function below is a dispatcher: the form types of EquationForms.hpp own the algebra.

void computeConstraintResidual(const CoordinateModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                               Eigen::VectorXd& phi) {
  const ElementView view(model, q);
  phi.resize(model.numConstraints());
  for (int i = 0; i < model.numConstraints(); ++i) {
    const ConstraintEquation& eq = model.equations[i];
    phi(i) = visitForm(eq.form, [&](auto form) { return form.value(view, eq); });
  }
}

namespace {

/// The rows of a sparse matrix written one after another: column indices and values, and where each row
/// starts.
struct RowsWritten {
  std::vector<int> columns;
  std::vector<double> values;
  std::vector<int> rowStart{0};
};

/**
 * @brief Appends one equation's gradient, as its form wrote it, as the next row of @p rows: the entries
 *        ordered by column (stable), repeated columns summed in the order written, exact zeros dropped.
 *
 * The same row, value for value, as setFromTriplets followed by prune(0.0) gave (it sums a column's entries
 * in triplet order and stores a row's columns in order), without the matrix of all triplets and the
 * column-major copy it was transposed from.
 */
void appendRow(GradientSink& entries, RowsWritten& rows) {
  for (size_t i = 1; i < entries.size(); ++i) {  // insertion sort: a row has a dozen entries at most
    const Eigen::Triplet<double> entry = entries[i];
    size_t k = i;
    for (; k > 0 && entries[k - 1].col() > entry.col(); --k)
      entries[k] = entries[k - 1];
    entries[k] = entry;
  }
  for (size_t i = 0; i < entries.size();) {
    const int column = entries[i].col();
    double value = entries[i].value();
    for (++i; i < entries.size() && entries[i].col() == column; ++i)
      value += entries[i].value();
    if (value != 0.0) {
      rows.columns.push_back(column);
      rows.values.push_back(value);
    }
  }
  rows.rowStart.push_back(static_cast<int>(rows.columns.size()));
}

/// @p parts, one after another, as a compressed row-major matrix with @p numColumns columns, its storage of
/// the exact size.
SparseJacobian toMatrix(const std::vector<const RowsWritten*>& parts, int numColumns) {
  size_t numRows = 0, numEntries = 0;
  for (const RowsWritten* rows : parts) {
    numRows += rows->rowStart.size() - 1;
    numEntries += rows->columns.size();
  }
  SparseJacobian matrix(static_cast<Eigen::Index>(numRows), numColumns);
  matrix.resizeNonZeros(static_cast<Eigen::Index>(numEntries));
  int* rowStart = matrix.outerIndexPtr();
  int offset = 0;
  size_t row = 0;
  for (const RowsWritten* rows : parts) {
    for (size_t r = 0; r + 1 < rows->rowStart.size(); ++r)
      rowStart[row++] = offset + rows->rowStart[r];
    std::copy(rows->columns.begin(), rows->columns.end(), matrix.innerIndexPtr() + offset);
    std::copy(rows->values.begin(), rows->values.end(), matrix.valuePtr() + offset);
    offset += static_cast<int>(rows->columns.size());
  }
  rowStart[row] = offset;
  return matrix;
}

/// Rows whose entries set the room reserved for the rest (writeRows).
constexpr int kSampledRows = 1024;

/// The rows [@p first, @p last) of the Jacobian, written in order, each from its own equation's few entries.
RowsWritten writeRows(const CoordinateModel& model, const ElementView& view, int first, int last) {
  RowsWritten rows;
  rows.rowStart.reserve(static_cast<size_t>(last - first) + 1);
  GradientSink entries;
  auto write = [&](int begin, int end) {
    for (int i = begin; i < end; ++i) {
      const ConstraintEquation& eq = model.equations[i];
      entries.clear();
      visitForm(eq.form, [&](auto form) { form.gradient(view, eq, i, entries); });
      appendRow(entries, rows);
    }
  };
  // Room for all the entries at once, from the first rows' count per row with a margin: grown by doubling
  // instead, the entries of a large model are copied about once more and touch about twice their memory in
  // fresh pages (what is reserved and never written is never touched).
  const int sampled = std::min(last, first + kSampledRows);
  write(first, sampled);
  const size_t perRow = rows.columns.size() / static_cast<size_t>(std::max(1, sampled - first)) + 1;
  const size_t expected = rows.columns.size() + 2 * perRow * static_cast<size_t>(last - sampled);
  rows.columns.reserve(expected);
  rows.values.reserve(expected);
  write(sampled, last);
  return rows;
}

}  // namespace

SparseJacobian computeConstraintJacobian(const CoordinateModel& model,
                                         const Eigen::Ref<const Eigen::VectorXd>& q) {
  return computeConstraintJacobian(model, q, false);
}

SparseJacobian computeConstraintJacobian(const CoordinateModel& model,
                                         const Eigen::Ref<const Eigen::VectorXd>& q, bool sideThread) {
  const ElementView view(model, q);
  const int m = model.numConstraints();
  if (!sideThread || m < core_detail::kSecondThreadEquations) {
    const RowsWritten rows = writeRows(model, view, 0, m);
    return toMatrix({&rows}, model.numCoordinates());
  }
  // Each row is its own equation's alone: the second half on another thread, then both copied into place.
  const int half = m / 2;
  core_detail::SideTask second(true, [&] { return writeRows(model, view, half, m); });
  const RowsWritten first = writeRows(model, view, 0, half);
  const RowsWritten rest = second.get();
  return toMatrix({&first, &rest}, model.numCoordinates());
}

Eigen::MatrixXd computeEquationHessian(const CoordinateModel& model,
                                       const Eigen::Ref<const Eigen::VectorXd>& q, int row) {
  const ElementView view(model, q);
  HessianSink triplets;
  const ConstraintEquation& eq = model.equations[row];
  visitForm(eq.form, [&](auto form) { form.hessian(view, eq, 1.0, triplets); });
  Eigen::MatrixXd hessian = Eigen::MatrixXd::Zero(model.numCoordinates(), model.numCoordinates());
  // The forms write both triangles ((a, b) block M, (b, a) block M^T); repeated entries add up.
  for (const Eigen::Triplet<double>& t : triplets)
    hessian(t.row(), t.col()) += t.value();
  return hessian;
}

Eigen::SparseMatrix<double> computeStressedHessian(const CoordinateModel& model,
                                                   const Eigen::Ref<const Eigen::VectorXd>& q,
                                                   const Eigen::Ref<const Eigen::VectorXd>& weights) {
  const ElementView view(model, q);
  HessianSink triplets;
  for (int i = 0; i < model.numConstraints(); ++i) {
    if (weights(i) == 0.0)
      continue;
    const ConstraintEquation& eq = model.equations[i];
    visitForm(eq.form, [&](auto form) { form.hessian(view, eq, weights(i), triplets); });
  }
  Eigen::SparseMatrix<double> hessian(model.numCoordinates(), model.numCoordinates());
  hessian.setFromTriplets(triplets.begin(), triplets.end());
  return hessian;
}

}  // namespace mobility_analysis
