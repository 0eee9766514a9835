// ConvertStopPoint: the test hook of convert (FLIPSCOPE_CONVERT_STOP, see Convert.h), apart so
// that the pieces convert is made of (SpillBuckets) pass its points without depending on it.
#pragma once

namespace flipscope {

/// Raises the signal FLIPSCOPE_CONVERT_STOP names when this is its pass through `point`
/// (Convert.h lists the points); nothing without it.
void testStopPoint(const char* point);

}  // namespace flipscope
