// SPDX-License-Identifier: MIT
// Assignment: Hungarian against brute force on random small matrices, forbidden pairs, greedy.
#include <gtest/gtest.h>
#include <wingman/localizer/association.hpp>

#include <functional>
#include <random>
#include <sstream>

namespace {

using wingman::localizer::greedy_assign;
using wingman::localizer::hungarian;
using wingman::localizer::kForbiddenCost;

struct Score {
  int pairs = 0;
  double cost = 0;
};

Score score(const Eigen::MatrixXd& c, const std::vector<int>& a) {
  Score s;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i] >= 0) {
      ++s.pairs;
      s.cost += c(static_cast<Eigen::Index>(i), a[i]);
    }
  return s;
}

// Every partial assignment over allowed pairs; best = most pairs, then least cost.
Score brute_force(const Eigen::MatrixXd& c) {
  Score best{-1, 0};
  std::vector<bool> used(static_cast<size_t>(c.cols()), false);
  std::function<void(int, Score)> rec = [&](int row, Score s) {
    if (row == c.rows()) {
      if (s.pairs > best.pairs || (s.pairs == best.pairs && s.cost < best.cost)) best = s;
      return;
    }
    rec(row + 1, s);  // row unassigned
    for (int j = 0; j < c.cols(); ++j) {
      if (used[j] || c(row, j) >= kForbiddenCost) continue;
      used[j] = true;
      rec(row + 1, Score{s.pairs + 1, s.cost + c(row, j)});
      used[j] = false;
    }
  };
  rec(0, Score{});
  return best;
}

bool valid(const Eigen::MatrixXd& c, const std::vector<int>& a) {
  if (static_cast<Eigen::Index>(a.size()) != c.rows()) return false;
  std::vector<bool> used(static_cast<size_t>(c.cols()), false);
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] < 0) continue;
    if (a[i] >= c.cols() || used[a[i]] || c(static_cast<Eigen::Index>(i), a[i]) >= kForbiddenCost) return false;
    used[a[i]] = true;
  }
  return true;
}

TEST(Hungarian, MatchesBruteForceOnRandomSmallMatrices) {
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> size(1, 6);
  std::uniform_real_distribution<double> cost(0.0, 20.0);
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  for (int k = 0; k < 500; ++k) {
    const int r = size(rng), c = size(rng);
    const double p_forbidden = (k % 3) * 0.25;  // 0, 25 %, 50 % forbidden
    Eigen::MatrixXd m(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) m(i, j) = coin(rng) < p_forbidden ? kForbiddenCost : cost(rng);
    const std::vector<int> a = hungarian(m);
    std::ostringstream shape;
    shape << "case " << k << ", " << r << "x" << c << ", forbidden " << p_forbidden << "\n" << m;
    ASSERT_TRUE(valid(m, a)) << shape.str();
    const Score got = score(m, a), want = brute_force(m);
    EXPECT_EQ(got.pairs, want.pairs) << shape.str();
    EXPECT_NEAR(got.cost, want.cost, 1e-9) << shape.str();
    // Greedy is valid but may be worse.
    const std::vector<int> g = greedy_assign(m);
    ASSERT_TRUE(valid(m, g)) << shape.str();
  }
}

TEST(Hungarian, BeatsGreedyWhereTheCheapestPairIsAWrongChoice) {
  Eigen::MatrixXd m(2, 2);
  m << 1, 2,  //
      2, 100;
  EXPECT_EQ(hungarian(m), (std::vector<int>{1, 0}));      // total 4
  EXPECT_EQ(greedy_assign(m), (std::vector<int>{0, 1}));  // total 101
}

TEST(Hungarian, ForbiddenPairsAreNeverReturnedEvenWhenCheaperOverall) {
  // Row 0 may only take column 0. The optimum keeps both rows assigned (total 55) rather than
  // giving row 1 its cheap column 0 (total 0.1, one pair).
  Eigen::MatrixXd m(2, 2);
  m << 5, kForbiddenCost,  //
      0.1, 50;
  EXPECT_EQ(hungarian(m), (std::vector<int>{0, 1}));
  // Only column 0 is allowed for both rows: the cheaper pair wins, the other row gets none.
  m(1, 1) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(hungarian(m), (std::vector<int>{-1, 0}));
  m.setConstant(kForbiddenCost);
  EXPECT_EQ(hungarian(m), (std::vector<int>{-1, -1}));
  m(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(hungarian(m), (std::vector<int>{-1, -1}));
}

TEST(Hungarian, HandlesEmptyAndRectangularMatrices) {
  EXPECT_TRUE(hungarian(Eigen::MatrixXd(0, 3)).empty());
  EXPECT_EQ(hungarian(Eigen::MatrixXd(2, 0)), (std::vector<int>{-1, -1}));
  Eigen::MatrixXd wide(2, 4);
  wide << 9, 9, 1, 9,  //
      9, 2, 9, 9;
  EXPECT_EQ(hungarian(wide), (std::vector<int>{2, 1}));
  const Eigen::MatrixXd tall = wide.transpose();
  EXPECT_EQ(hungarian(tall), (std::vector<int>{-1, 1, 0, -1}));
}

}  // namespace
