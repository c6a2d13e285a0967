// SPDX-License-Identifier: MIT
// Assignment of detections to tracks: optimal (Hungarian) and greedy nearest-neighbour.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace wingman::localizer {

/// Costs at or above this value (and NaN or infinite ones) mark a forbidden pair, e.g. a detection
/// outside a track's gate.
inline constexpr double kForbiddenCost = 1e12;

/// True when cost c marks a forbidden pair.
inline bool is_forbidden(double c) { return !(c < kForbiddenCost) || c != c; }

/// Optimal assignment of rows (tracks) to columns (detections), each used at most once: among the
/// assignments with the most allowed pairs, one with the least total cost (global nearest
/// neighbour). Rectangular matrices are fine. Returns, per row, its column or -1 for none; a
/// forbidden pair is never returned. Kuhn-Munkres with potentials, O(n^2 m) for n <= m (the
/// matrix is transposed otherwise); forbidden entries are replaced by a cost larger than twice the
/// sum of all allowed |costs| and dropped afterwards.
std::vector<int> hungarian(const Eigen::MatrixXd& cost);

/// Greedy assignment: repeatedly takes the cheapest remaining allowed pair. Not optimal; kept as
/// the simpler option and as a reference. Same return convention as hungarian().
std::vector<int> greedy_assign(const Eigen::MatrixXd& cost);

}  // namespace wingman::localizer
