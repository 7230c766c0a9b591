#include "taiga/trees/tree_files.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "taiga/core/errors.hpp"

namespace taiga::trees {
namespace {

using ::testing::HasSubstr;

std::string errorOf(const std::string& text) {
  try {
    parseTreesCsv(text, "t.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TreeFiles, ReadsTheSimulatorsAndTaigasListsByColumnName) {
  const auto sim = parseTreesCsv(
      "id,x_m,y_m,z_m,dbh_m,height_m,lean_deg,lean_azimuth_deg,species,x_bh_m,y_bh_m\n"
      "7,3.1,24.2,-0.26,0.265,19.2,1.8,313.6,pine,3.17,24.14\n",
      "sim");
  ASSERT_EQ(sim.size(), 1u);
  EXPECT_EQ(sim[0].id, 7);
  EXPECT_EQ(sim[0].bh_xy_m, Eigen::Vector2d(3.17, 24.14));  // breast height, not the base
  EXPECT_DOUBLE_EQ(sim[0].dbh_m, 0.265);
  EXPECT_DOUBLE_EQ(sim[0].lean_deg, 1.8);
  EXPECT_DOUBLE_EQ(sim[0].lean_azimuth_deg, 313.6);
  // Without breast-height columns the x_m, y_m columns are taken; without heights NaN.
  const auto plain = parseTreesCsv("dbh_m,y_m,x_m,id\r\n0.3,2,1,4\r\n\n", "plain");
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_EQ(plain[0].bh_xy_m, Eigen::Vector2d(1, 2));
  EXPECT_TRUE(std::isnan(plain[0].height_m));
  EXPECT_TRUE(std::isnan(plain[0].lean_deg));
}

TEST(TreeFiles, BadInputNamesTheLineAndColumn) {
  EXPECT_THAT(errorOf(""), HasSubstr("t.csv: empty file"));
  EXPECT_THAT(errorOf("id,x_m,y_m\n"), HasSubstr("no column 'dbh_m'"));
  EXPECT_THAT(errorOf("id,x_m,y_m,dbh_m\n1,2,3\n"), HasSubstr("t.csv:2: 3 values"));
  EXPECT_THAT(errorOf("id,x_m,y_m,dbh_m\n1,2,nan,0.3\n"), HasSubstr("t.csv:2: column 'y_m'"));
  EXPECT_THAT(errorOf("id,x_m,y_m,dbh_m\n1,2,3,0.3\n1e300,2,3,0.3\n"),
              HasSubstr("t.csv:3: column 'id'"));
  EXPECT_THROW(readTreesCsv("/nonexistent/trees.csv"), InputError);
}

}  // namespace
}  // namespace taiga::trees
