// Output confinement: names that end up in output paths (a task's name, a prefix) must stay
// inside the output folder, and an output must never replace an input.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"

namespace recruit {

// OK iff `name` can be one file-name component: 1..100 characters from [A-Za-z0-9._-+],
// not starting with '.' (so no "..", no hidden files), no '/', no control characters.
// `what` names the value in the error, e.g. "task.json: name".
Status CheckFileNameComponent(const std::string& name, const std::string& what);

// OK iff `out` is not the same file as any of `inputs` (same path, or an existing file that is
// the same inode through another path or a link). `inputs` are (label, path) pairs.
Status CheckNotAnInput(const std::string& out, const std::string& out_label,
                       const std::vector<std::pair<std::string, std::string>>& inputs);

}  // namespace recruit
