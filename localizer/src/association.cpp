// SPDX-License-Identifier: MIT
// Hungarian (Kuhn-Munkres with potentials) and greedy assignment with forbidden pairs.
#include "wingman/localizer/association.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace wingman::localizer {
namespace {

// Kuhn-Munkres with row/column potentials for n <= m; a is n x m with finite entries.
// Returns the column of each row (every row is assigned).
std::vector<int> solve_rows_le_cols(const Eigen::MatrixXd& a) {
  const int n = static_cast<int>(a.rows());
  const int m = static_cast<int>(a.cols());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);  // p[j]: row (1-based) assigned to column j; 0 = none
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<bool> used(m + 1, false);
    do {
      used[j0] = true;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = a(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> col_of_row(n, -1);
  for (int j = 1; j <= m; ++j)
    if (p[j] != 0) col_of_row[p[j] - 1] = j - 1;
  return col_of_row;
}

}  // namespace

std::vector<int> hungarian(const Eigen::MatrixXd& cost) {
  const Eigen::Index rows = cost.rows();
  const Eigen::Index cols = cost.cols();
  std::vector<int> result(static_cast<size_t>(rows), -1);
  if (rows == 0 || cols == 0) return result;

  double sum_abs = 0;
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index j = 0; j < cols; ++j)
      if (!is_forbidden(cost(i, j))) sum_abs += std::abs(cost(i, j));
  const double big = 2.0 * sum_abs + 1.0;  // one forbidden pair costs more than any allowed difference
  Eigen::MatrixXd a(rows, cols);
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index j = 0; j < cols; ++j) a(i, j) = is_forbidden(cost(i, j)) ? big : cost(i, j);

  if (rows <= cols) {
    const std::vector<int> c = solve_rows_le_cols(a);
    for (Eigen::Index i = 0; i < rows; ++i) result[i] = c[i];
  } else {
    const std::vector<int> r = solve_rows_le_cols(a.transpose());  // row of each column
    for (Eigen::Index j = 0; j < cols; ++j) result[r[j]] = static_cast<int>(j);
  }
  for (Eigen::Index i = 0; i < rows; ++i)
    if (result[i] >= 0 && is_forbidden(cost(i, result[i]))) result[i] = -1;
  return result;
}

std::vector<int> greedy_assign(const Eigen::MatrixXd& cost) {
  std::vector<std::tuple<double, int, int>> pairs;
  for (Eigen::Index i = 0; i < cost.rows(); ++i)
    for (Eigen::Index j = 0; j < cost.cols(); ++j)
      if (!is_forbidden(cost(i, j))) pairs.emplace_back(cost(i, j), static_cast<int>(i), static_cast<int>(j));
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> result(static_cast<size_t>(cost.rows()), -1);
  std::vector<bool> col_used(static_cast<size_t>(cost.cols()), false);
  for (const auto& [c, i, j] : pairs) {
    if (result[i] >= 0 || col_used[j]) continue;
    result[i] = j;
    col_used[j] = true;
  }
  return result;
}

}  // namespace wingman::localizer
