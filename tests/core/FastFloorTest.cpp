// fastFloor against std::floor: every float around the edges that matter, and random ones.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <type_traits>

#include "core/FastFloor.h"

namespace flipscope {
namespace {

template <class T>
void expectSameAsStd(T v) {
  const T fast = fastFloor(v), reference = std::floor(v);
  if (std::isnan(reference)) {
    EXPECT_TRUE(std::isnan(fast)) << v;
  } else {
    // Bit for bit, but that -0 may give +0 (the contract); -0.5 gives -1.
    using Bits = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
    if (reference == T(0)) {
      EXPECT_EQ(fast, T(0)) << v;
    } else {
      EXPECT_EQ(std::bit_cast<Bits>(fast), std::bit_cast<Bits>(reference)) << v << " gave " << fast << ", not " << reference;
    }
  }
}

template <class T>
void expectEdges(T limit) {  // limit: 2^23 or 2^52, from where on every value is an integer
  const T inf = std::numeric_limits<T>::infinity();
  for (T v : {T(0), T(-0.0), T(0.5), T(-0.5), T(1), T(-1), T(1.5), T(-1.5), T(2.999), T(-2.999), inf, -inf,
              std::numeric_limits<T>::quiet_NaN(), std::numeric_limits<T>::denorm_min(),
              -std::numeric_limits<T>::denorm_min(), std::numeric_limits<T>::max(), std::numeric_limits<T>::lowest(),
              limit, -limit}) {
    expectSameAsStd(v);
    expectSameAsStd(std::nextafter(v, inf));
    expectSameAsStd(std::nextafter(v, -inf));
  }
}

TEST(FastFloor, EqualsStdFloorOnTheEdges) {
  expectEdges(8388608.0f);
  expectEdges(4503599627370496.0);
}

TEST(FastFloor, EqualsStdFloorOnRandomValues) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> wide(-1e7, 1e7), narrow(-4, 4);
  for (int i = 0; i < 200000; ++i) {
    expectSameAsStd(float(wide(random)));
    expectSameAsStd(float(narrow(random)));
    expectSameAsStd(wide(random));
    expectSameAsStd(narrow(random) * 1e15);
  }
  const glm::dvec3 v = fastFloor(glm::dvec3(-0.25, 2.5, -3.0));
  EXPECT_EQ(v, glm::dvec3(-1, 2, -3));
}

}  // namespace
}  // namespace flipscope
