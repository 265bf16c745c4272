// core/strings.h: the name lists of error messages.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/strings.h"

namespace morphfem {
namespace {

TEST(Join, PutsTheSeparatorBetweenItemsOnly) {
  EXPECT_EQ(join(std::vector<std::string>{}, ", "), "");
  EXPECT_EQ(join(std::vector<std::string>{"a"}, ", "), "a");
  EXPECT_EQ(join(std::vector<std::string>{"a", "b", "c"}, ", "), "a, b, c");
  EXPECT_EQ(join(std::set<std::string>{"b", "a"}, "; "), "a; b");  // a set's own order
}

TEST(Join, KeepsEmptyItemsInTheirPlace) {
  // an empty first name still gets its separator, so the count of items can be read off
  EXPECT_EQ(join(std::vector<std::string>{"", "b"}, ", "), ", b");
}

TEST(Join, NamesItemsThroughAProjection) {
  struct Level {
    std::string name;
    double h;
  };
  const std::vector<Level> levels{{"0", 0.03}, {"1", 0.02}};
  EXPECT_EQ(join(levels, ", ", [](const Level& l) { return l.name; }), "0, 1");
  EXPECT_EQ(join(std::vector<std::string>{"x", "y"}, "', '", [](const std::string& s) { return s; }), "x', 'y");
}

TEST(JoinKeys, ListsAMapsKeysInOrder) {
  const std::map<std::string, int> registry{{"neo_hookean", 1}, {"mooney_rivlin", 2}, {"gent", 3}};
  EXPECT_EQ(join_keys(registry, ", "), "gent, mooney_rivlin, neo_hookean");
  EXPECT_EQ(join_keys(std::map<std::string, int>{}, ", "), "");
}

}  // namespace
}  // namespace morphfem
