#include <gtest/gtest.h>

#include <cmath>

#include "cohort/balance/bands.h"

using namespace cohort::balance;

TEST(Bands, SharesGiveContiguousUnitAlignedCover) {
  const std::vector<double> shares{1.0, 2.0, 1.0};
  const auto bands = bands_from_shares(400, shares);
  ASSERT_EQ(bands.size(), 3u);
  EXPECT_EQ(check_bands(400, bands), "");
  EXPECT_EQ(bands[0], (Band{0, 100}));
  EXPECT_EQ(bands[1], (Band{100, 300}));
  EXPECT_EQ(bands[2], (Band{300, 400}));
}

TEST(Bands, LastBandTakesThePartialUnit) {
  const auto bands = equal_bands(30, 2);  // 8 units, the last holds 2 rows
  EXPECT_EQ(check_bands(30, bands), "");
  EXPECT_EQ(bands[0], (Band{0, 16}));
  EXPECT_EQ(bands[1], (Band{16, 30}));
}

TEST(Bands, EveryTracerKeepsOneUnitEvenWithATinyShare) {
  const std::vector<double> shares{1e-9, 1000.0, 1e-9};
  const auto bands = bands_from_shares(64, shares);
  EXPECT_EQ(check_bands(64, bands), "");
  EXPECT_EQ(bands[0].rows(), kRowsPerUnit);
  EXPECT_EQ(bands[2].rows(), kRowsPerUnit);
}

TEST(Bands, MoreTracersThanUnitsLeavesTrailingBandsEmpty) {
  const auto bands = equal_bands(8, 4);  // 2 units for 4 tracers
  EXPECT_EQ(check_bands(8, bands), "");
  EXPECT_EQ(bands[0].rows(), 4);
  EXPECT_EQ(bands[1].rows(), 4);
  EXPECT_TRUE(bands[2].empty());
  EXPECT_TRUE(bands[3].empty());
}

TEST(Bands, BadSharesFallBackToEqual) {
  const std::vector<double> shares{0.0, -1.0, std::nan("")};
  const auto bands = bands_from_shares(120, shares);
  EXPECT_EQ(check_bands(120, bands), "");
  EXPECT_EQ(bands[0].rows(), 40);
  EXPECT_EQ(bands[1].rows(), 40);
}

TEST(Bands, CheckerNamesTheProblem) {
  const std::vector<Band> gap{{0, 8}, {12, 16}};
  EXPECT_NE(check_bands(16, gap).find("does not start"), std::string::npos);
  const std::vector<Band> misaligned{{0, 6}, {6, 16}};
  EXPECT_NE(check_bands(16, misaligned).find("unit boundary"), std::string::npos);
  const std::vector<Band> short_cover{{0, 8}};
  EXPECT_NE(check_bands(16, short_cover).find("frame has 16"), std::string::npos);
}

TEST(Bands, RelaxedRulesAllowEmptyBandsAndFineCutsButNotAnAllEmptyDivision) {
  const BandRules fine{1, true};
  const std::vector<Band> benched{{0, 0}, {0, 13}, {13, 13}, {13, 16}};
  EXPECT_EQ(check_bands(16, benched, fine), "");
  EXPECT_NE(check_bands(16, benched), "") << "the paper's rules still hold by default";
  EXPECT_NE(check_bands(16, std::vector<Band>{{0, 13}, {13, 16}}).find("unit boundary"), std::string::npos);
  EXPECT_EQ(check_bands(16, std::vector<Band>{{0, 0}, {0, 12}, {12, 16}}, BandRules{kRowsPerUnit, true}), "");
  EXPECT_NE(check_bands(16, std::vector<Band>{{0, 16}, {16, 16}}, BandRules{kRowsPerUnit, false}).find("empty"), std::string::npos);
  EXPECT_NE(check_bands(16, std::vector<Band>{{0, 0}, {0, 0}}, fine).find("every band is empty"), std::string::npos);
  EXPECT_NE(check_bands(16, std::vector<Band>{{0, 8}, {8, 16}}, BandRules{0, true}).find("row unit"), std::string::npos);
}
