// GL tests (label `gl`) need an EGL device with OpenGL 4.5: Mesa llvmpipe here and in CI. Without
// one they skip, unless FLIPSCOPE_REQUIRE_GL is set (CI sets it): then a missing device fails
// the test, so that a broken GL setup cannot pass as a row of skips.
#pragma once

#include <cstdlib>

#include <gtest/gtest.h>

#define FLIPSCOPE_SKIP_WITHOUT_GL(reason)                                                          \
  do {                                                                                             \
    if (std::getenv("FLIPSCOPE_REQUIRE_GL"))                                                       \
      FAIL() << "FLIPSCOPE_REQUIRE_GL is set, but there is no EGL/OpenGL 4.5 device: " << reason; \
    else                                                                                           \
      GTEST_SKIP() << "no EGL/OpenGL 4.5 device: " << reason;                                      \
  } while (false)
