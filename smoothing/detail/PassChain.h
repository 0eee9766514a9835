// A filter's chain of passes, each reading the image the one before it wrote: the first reads
// the filter's input, the last writes its output, the others alternate between two scratch
// images the chain creates on first use (frame-sized, on the device of that first use).
//
//   detail::PassChain mChain;
//   mChain.run(device, depth, output, mOptions.iterations, [&](int, ScreenImage from, ScreenImage to) {
//     device.run(kStep, params, {from}, to);
//   });
#pragma once

#include <array>
#include <optional>

#include "smoothing/ScreenDevice.h"

namespace flipscope::detail {

class PassChain {
 public:
  /// Issues `count` (at least 1) passes: `pass(i, from, to)` runs pass i from image `from` to
  /// image `to` (never the same image).
  template <class Pass>
  void run(ScreenDevice& device, ScreenImage input, ScreenImage output, int count, Pass&& pass) {
    if (count > 1 && !mScratch) mScratch = {device.createFrameImage(), device.createFrameImage()};
    ScreenImage from = input;
    for (int i = 0; i < count; ++i) {
      const ScreenImage to = i + 1 == count ? output : (*mScratch)[i % 2];
      pass(i, from, to);
      from = to;
    }
  }

 private:
  std::optional<std::array<ScreenImage, 2>> mScratch;
};

}  // namespace flipscope::detail
