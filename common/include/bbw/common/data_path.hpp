// Where a bbw binary finds the files it ships with (config/, scripts/): no source path is
// compiled into a product binary. In order:
//   1. $BBW_DATA_DIR, when set (must be a directory);
//   2. <directory of this executable>/../share/bbw (the install layout, `cmake --install`; the
//      build tree mirrors it: build/share/bbw links to the source tree's config/ and scripts/).
// Throws std::runtime_error naming what it tried when neither holds `relative`.
#pragma once

#include <string>

namespace bbw::data {

// The directory of the running executable (/proc/self/exe).
std::string executable_dir();
// The data root (see above) that holds `relative`, joined with it.
std::string path(const std::string& relative);
// The data root itself: the folder that holds config/.
std::string root();

}  // namespace bbw::data
