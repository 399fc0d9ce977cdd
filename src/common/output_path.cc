#include "common/output_path.h"

#include <cctype>
#include <filesystem>

#include "common/short_text.h"

namespace recruit {

Status CheckFileNameComponent(const std::string& name, const std::string& what) {
  const std::string allowed =
      "; allowed: 1 to 100 of letters, digits, '.', '_', '-', '+', not starting with '.' (it is "
      "used in output file names, which must stay inside --out)";
  if (name.empty() || name.size() > 100 || name[0] == '.') {
    return Error{what + " '" + ShortText(name) + "' cannot be used in a file name" + allowed};
  }
  for (char c : name) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (!(std::isalnum(u) || c == '.' || c == '_' || c == '-' || c == '+')) {
      return Error{what + " '" + ShortText(name) + "' cannot be used in a file name" + allowed};
    }
  }
  return Status::Ok();
}

Status CheckNotAnInput(const std::string& out, const std::string& out_label,
                       const std::vector<std::pair<std::string, std::string>>& inputs) {
  namespace fs = std::filesystem;
  for (const auto& [label, input] : inputs) {
    if (input.empty()) continue;
    std::error_code ec;
    const bool same_path =
        fs::absolute(out, ec).lexically_normal() == fs::absolute(input, ec).lexically_normal();
    if (same_path || fs::equivalent(out, input, ec)) {
      return Error{out_label + " '" + ShortText(out) + "' is the same file as " + label + " '" +
                       ShortText(input) + "'; refusing to overwrite an input",
                   ErrorCode::kUsage};
    }
  }
  return Status::Ok();
}

}  // namespace recruit
