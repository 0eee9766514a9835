// Numbers as text: short for messages people read, exact for text that is read back (command
// lines written into scripts, values compared with a store's).
#pragma once

#include <string>

namespace flipscope {

/// Six significant digits, as printf's %g: "0.00446289", "-1", "1e+30", "nan", "inf".
std::string numberText(double value);
/// The shortest decimal that reads back as `value` exactly (std::to_chars): "0.1", "0.30000000000000004".
std::string exactNumberText(double value);

}  // namespace flipscope
