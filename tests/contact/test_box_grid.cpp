// The broad phase's uniform grid (contact/box_grid.h): against brute force over random
// boxes, every box that contains a point is listed in the point's cell, and every box
// that overlaps a query box is found by near(); boxes on negative coordinates and boxes
// larger than a cell are included.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <vector>

#include "contact/box_grid.h"

using namespace morphfem;

namespace {

struct Box {
  Eigen::Vector3d lo, hi;
};

bool contains(const Box& b, const Eigen::Vector3d& y) {
  return (y.array() >= b.lo.array()).all() && (y.array() <= b.hi.array()).all();
}

bool overlap(const Box& a, const Box& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

// Boxes with corners in [-0.1, 0.1]^3 m and sides up to 0.05 m (several 0.01 m cells).
std::vector<Box> random_boxes(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> corner(-0.1, 0.1), side(0.0, 0.05);
  std::vector<Box> boxes(n);
  for (Box& b : boxes) {
    b.lo = Eigen::Vector3d(corner(rng), corner(rng), corner(rng));
    b.hi = b.lo + Eigen::Vector3d(side(rng), side(rng), side(rng));
  }
  return boxes;
}

}  // namespace

TEST(BoxGrid, ThePointsCellListsEveryBoxThatContainsIt) {
  std::mt19937 rng(7);
  const std::vector<Box> boxes = random_boxes(rng, 200);
  BoxGrid grid(0.01);
  for (int i = 0; i < static_cast<int>(boxes.size()); ++i) grid.insert(i, boxes[i].lo, boxes[i].hi);
  std::uniform_real_distribution<double> coordinate(-0.12, 0.12);
  int containing = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d y(coordinate(rng), coordinate(rng), coordinate(rng));
    const std::vector<int>* listed = grid.at(y);
    const std::set<int> ids = listed ? std::set<int>(listed->begin(), listed->end()) : std::set<int>{};
    for (int i = 0; i < static_cast<int>(boxes.size()); ++i)
      if (contains(boxes[i], y)) {
        ++containing;
        EXPECT_TRUE(ids.count(i)) << "box " << i << " contains " << y.transpose() << " but is not listed";
      }
  }
  EXPECT_GT(containing, 100);  // the check saw enough containing boxes to mean something
}

TEST(BoxGrid, NearFindsEveryOverlappingBox) {
  std::mt19937 rng(11);
  const std::vector<Box> boxes = random_boxes(rng, 200);
  BoxGrid grid(0.01);
  for (int i = 0; i < static_cast<int>(boxes.size()); ++i) grid.insert(i, boxes[i].lo, boxes[i].hi);
  int overlapping = 0;
  std::size_t found_total = 0;
  for (const Box& query : random_boxes(rng, 300)) {
    std::set<int> ids;
    grid.near(query.lo, query.hi, ids);
    found_total += ids.size();
    for (int i = 0; i < static_cast<int>(boxes.size()); ++i)
      if (overlap(boxes[i], query)) {
        ++overlapping;
        EXPECT_TRUE(ids.count(i)) << "box " << i << " overlaps the query box but was not found";
      }
  }
  EXPECT_GT(overlapping, 100);
  // A broad phase, not a full list: it returns far fewer than all 200 boxes per query.
  EXPECT_LT(found_total, 300u * 200u / 4u);
}
