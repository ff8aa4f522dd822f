#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "mobility_analysis/ConstraintJacobian.hpp"

namespace mobility_analysis {

/**
 * @brief A left null vector y of the constraint Jacobian (\f$ y^T \Phi_q = 0 \f$): a self-stress.
 *
 * Sparse, as (equation, coefficient) pairs by increasing equation. Coefficients refer to the rows scaled to
 * unit norm (the scaling every elimination here works in).
 */
using SelfStress = std::vector<std::pair<int, double>>;

/// @return The equations of @p stress (its support), increasing.
std::vector<int> supportOf(const SelfStress& stress);

/**
 * @brief Incremental sparse elimination with threshold partial pivoting over columns only.
 *
 * Rows are added one at a time and never reordered; each row, scaled, is reduced by the pivot rows made
 * before it. If what remains is below the tolerance the row is dependent on the rows added before it,
 * otherwise it becomes a pivot row at the column of lowest priority among its entries within
 * tolerances::kPivotThreshold of its largest. Pivot rows are pooled (immutable once made), and with their
 * multipliers kept each dependent row's dependency can be traced back to the rows it combines. Cost is
 * proportional to the fill, which stays small when the rows and the column priorities sweep the structure in
 * the same direction.
 */
class SparseElimination {
 public:
  /**
   * @param[in] numColumns n.
   * @param[in] columnPriority pivot preference of each column, lower first (dim n); empty: the column index.
   * @param[in] tolerance relative threshold: a row whose reduced norm is at most this is dependent [-].
   * @param[in] keepMultipliers whether to keep what traceDependency needs.
   * @param[in] pivotThreshold any entry at least this fraction of the reduced row's largest may be its pivot
   * (tolerances::kPivotThreshold by default; 1: strict partial pivoting, the largest entry).
   */
  SparseElimination(int numColumns, std::vector<int> columnPriority, double tolerance, bool keepMultipliers,
                    double pivotThreshold = -1.0);

  /// What adding one row found.
  struct Step {
    bool dependent = false;
    double residual = 0.0;  ///< Norm of the reduced row (the row scaled as given) [-].
  };

  /**
   * @brief Reduces row @p r of @p J, multiplied by @p scale, and keeps it as a pivot row when it is
   * independent.
   *
   * Afterwards multipliers() holds the reduction, J_r scale = sum_k m_k P_k + residual.
   */
  Step addRow(const SparseJacobian& J, int r, double scale);

  /**
   * @brief The first half of addRow: reduces row @p r of @p J, multiplied by @p scale, and says what was
   * found, without keeping anything. keep() then keeps it as a pivot row, whatever step.dependent said; the
   * next reduce or addRow forgets it.
   */
  Step reduce(const SparseJacobian& J, int r, double scale) { return reduceOver(J, r, scale, rank()); }
  /**
   * @brief reduce() against the first @p numPivots pivot rows only: the reduction, and multipliers(), that
   * row @p r had when it was added with that many pivot rows kept, to the bit (pivot rows never change once
   * kept, and a reduction reads no other). The sweep traces a dependent row's stress after the elimination
   * has gone past it (FindsAhead.hpp). keep() must not follow.
   */
  Step reduceOver(const SparseJacobian& J, int r, double scale, int numPivots);
  /// Keeps the row reduce() last reduced as a pivot row (its reduced norm must be positive).
  void keep();
  /// Room for @p rows pivot rows holding @p entries entries in all (a hint: the storage still grows).
  void reserve(size_t rows, size_t entries);
  /**
   * @brief Forgets every row, for a new elimination over @p numColumns columns with the same tolerance and
   * options, keeping the storage. Why: a local search eliminates thousands of balls of a hundred rows (one
   * per redundant row of a grid of continuous bars); a fresh elimination per ball grew every pool from empty,
   * and its allocations cost about as much as the arithmetic.
   *
   * Only for the default priorities (the column index): given ones are for the columns they were given for.
   */
  void reset(int numColumns);

  /**
   * @brief The distance of row @p r of @p J, multiplied by @p scale, from the span of the pivot rows: the
   * residual an orthogonal (Gram–Schmidt) test would compare with the tolerance.
   *
   * addRow's residual is the reduced row, zero at the pivot columns; it is never below this distance, and
   * where the pivot rows are nearly dependent (a long ring) it carries their rounding, amplified. The
   * distance is read off a basis of the right null space of the pivot rows (nullSpace), orthonormalised:
   * |Q^T x|. Cost: nullSpace's, and a dense QR of its vectors.
   * @param[in] maxNullity give up (return nothing) when more than this many columns hold no pivot.
   */
  std::optional<double> distanceFromPivotRows(const SparseJacobian& J, int r, double scale,
                                              size_t maxNullity) const;

  /// Multipliers (pivot k, m_k) of the last row added.
  const std::vector<std::pair<int, double>>& multipliers() const { return multipliers_; }

  /**
   * @brief The dependency of a dependent row: y with y_row = 1 over @p row and the independent rows it
   * combines.
   * @param[in] row the dependent row.
   * @param[in] multipliers its reduction (multipliers() right after it was added).
   * @param[in] maxSupport give up (return nothing) once the dependency has more equations than this; 0: no
   * limit.
   */
  std::optional<SelfStress> traceDependency(int row, const std::vector<std::pair<int, double>>& multipliers,
                                            size_t maxSupport = 0);

  int rank() const { return static_cast<int>(origin_.size()); }
  /**
   * @brief A basis of the right null space of the rows added so far (the first-order motions when every row
   * of J was added): one vector per column that never became a pivot, 1 there and 0 at the other free
   * columns, the pivot columns by back-substitution from the latest pivot row (each pivot row is zero at the
   * pivot columns of earlier ones). Cost: the pivot rows each vector reaches, per vector.
   * @param[in] maxVectors give up (return nothing) when there are more free columns than this.
   */
  std::optional<std::vector<Eigen::VectorXd>> nullSpace(size_t maxVectors) const;
  int numColumns() const { return static_cast<int>(pivotOfColumn_.size()); }
  double smallestKeptPivot() const;  ///< 0 when no row was kept.
  double largestDroppedResidual() const { return largestDropped_; }
  /// Entries kept so far, of the pivot rows and their multipliers: the fill, which the time follows.
  size_t storedEntries() const { return entries_.size() + pivotMultipliers_.size(); }
  /// Pivot rows subtracted over every reduction so far: the work, where a row is reduced through a chain of
  /// pivot rows that each bring in the next (no fill, but time).
  size_t reductionSteps() const { return reductionSteps_; }

 private:
  int priority(int column) const { return columnPriority_.empty() ? column : columnPriority_[column]; }

  /**
   * A set of pivot indices taken smallest first: a bit per pivot, and a bit per 64-bit word of them that is
   * not zero. It holds the pivots to reduce the current row by (reduce) and, counted from the latest, those
   * a dependency still has to expand (traceDependency). Why not a heap: a row of a local ball meets about
   * five pivots, and the heap's pushes and pops cost more than reducing by them; here a push sets two bits and
   * a pop reads the lowest. Both uses only push above what they last took (P_k is zero at the pivot columns
   * of earlier pivots, so fill only reaches later ones; a pivot's multipliers refer to earlier ones), so each
   * row or dependency scans the summary words once.
   */
  class PivotQueue {
   public:
    /// Room for pivots 0 .. @p size - 1.
    void resize(size_t size) {
      bits_.resize((size + 63) / 64, 0);
      words_.resize((bits_.size() + 63) / 64, 0);
    }
    bool empty() const { return size_ == 0; }
    void push(int k) {
      const size_t word = static_cast<size_t>(k) >> 6;
      const uint64_t bit = uint64_t{1} << (k & 63);
      if ((bits_[word] & bit) != 0)
        return;
      bits_[word] |= bit;
      words_[word >> 6] |= uint64_t{1} << (word & 63);
      lowestSummary_ = std::min(lowestSummary_, word >> 6);
      ++size_;
    }
    /// Empties the queue.
    void clear() {
      while (!empty())
        pop();
    }
    /// Removes and returns the smallest pivot (the queue must not be empty).
    int pop() {
      while (words_[lowestSummary_] == 0)
        ++lowestSummary_;
      const size_t word = (lowestSummary_ << 6) + static_cast<size_t>(__builtin_ctzll(words_[lowestSummary_]));
      const int k = static_cast<int>((word << 6) + static_cast<size_t>(__builtin_ctzll(bits_[word])));
      bits_[word] &= bits_[word] - 1;
      if (bits_[word] == 0)
        words_[word >> 6] &= ~(uint64_t{1} << (word & 63));
      if (--size_ == 0)
        lowestSummary_ = kNone;
      return k;
    }

   private:
    static constexpr size_t kNone = static_cast<size_t>(-1);
    std::vector<uint64_t> bits_, words_;
    size_t size_ = 0;
    size_t lowestSummary_ = kNone;  ///< No summary word below it is set.
  };

  std::vector<int> columnPriority_;
  double tolerance_;
  double pivotThreshold_;
  bool keepMultipliers_;

  // Pivot rows P_k = scale J_origin(k) - sum_j m_kj P_j, pooled: entries of P_k are
  // entries_[entryStart_[k] .. entryStart_[k+1]), its multipliers likewise.
  std::vector<int> origin_, column_;
  std::vector<double> pivot_;
  std::vector<size_t> entryStart_ = {0}, multiplierStart_ = {0};
  std::vector<std::pair<int, double>> entries_, pivotMultipliers_;
  std::vector<int> pivotOfColumn_;

  // Workspace, reused across rows.
  std::vector<double> values_;
  std::vector<char> present_;
  std::vector<int> touched_;
  PivotQueue pending_;  ///< Empty between rows; a member so that no row allocates one.
  std::vector<std::pair<int, double>> multipliers_;
  // traceDependency's workspace: coefficients and flags by pivot (zero between calls), the pivots to expand
  // and those it touched.
  std::vector<double> coefficient_;
  std::vector<char> traced_;
  PivotQueue traceQueue_;
  std::vector<int> traceSeen_;

  double smallestKept_ = -1.0;
  double largestDropped_ = 0.0;
  int reducedRow_ = -1;         ///< The row the workspace holds reduced (reduce).
  size_t reductionSteps_ = 0;
  double reducedLargest_ = 0.0;  ///< Its largest entry in magnitude.
};

}  // namespace mobility_analysis
