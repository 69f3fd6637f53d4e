#include "util/output_paths.hpp"

#include <filesystem>
#include <system_error>

#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {
namespace fs = std::filesystem;

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec)) return true;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return ca == cb;
}
}  // namespace

void check_output_paths(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath& out = outputs[i];
    if (out.path.empty()) continue;
    for (const NamedPath& in : inputs)
      if (!in.path.empty() && same_file(out.path, in.path))
        throw UserError(out.option + " " + out.path + " would overwrite the input " + in.path +
                        (in.option == "input" ? "" : " (" + in.option + ")"));
    for (size_t j = 0; j < i; ++j)
      if (!outputs[j].path.empty() && same_file(out.path, outputs[j].path))
        throw UserError(out.option + " " + out.path + " is also the " + outputs[j].option + " output");
    require_writable_dir(out.path);
  }
}

}  // namespace stipplot
