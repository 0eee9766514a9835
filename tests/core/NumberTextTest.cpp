#include "core/NumberText.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

namespace flipscope {
namespace {

TEST(NumberText, MessagesGetSixSignificantDigitsWithoutTrailingZeros) {
  EXPECT_EQ(numberText(-1.0), "-1");
  EXPECT_EQ(numberText(0.00446289123), "0.00446289");
  EXPECT_EQ(numberText(1e30), "1e+30");
  EXPECT_EQ(numberText(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(numberText(std::numeric_limits<double>::max()), "1.79769e+308");
  EXPECT_TRUE(std::isnan(std::stod(numberText(std::nan("")))));
}

TEST(NumberText, ExactTextIsTheShortestThatReadsBackAsTheSameDouble) {
  EXPECT_EQ(exactNumberText(0.1), "0.1");
  EXPECT_EQ(exactNumberText(0.1 + 0.2), "0.30000000000000004");
  for (double v : {0.00446289123, 1.0 / 3.0, -2.5e-300, 6.02214076e23, std::numeric_limits<double>::max(),
                   std::numeric_limits<double>::denorm_min()})
    EXPECT_EQ(std::strtod(exactNumberText(v).c_str(), nullptr), v) << exactNumberText(v);
}

}  // namespace
}  // namespace flipscope
