// Linked into every test binary: the shipped data (models/identified/) is the source tree's, as
// `recruit` sets it (common/data_path.h), before any test runs.
#include "common/data_path.h"

namespace file_test_data_dir {
const bool kDataDirSet = (recruit::SetDataDir(RECRUIT_SOURCE_DIR), true);
}  // namespace file_test_data_dir
