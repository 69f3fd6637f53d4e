#pragma once
// Errors a user can act on. The CLI prints what() as one line and exits non-zero;
// anything else escaping is a bug and is reported as an internal error.
#include <stdexcept>
#include <string>

namespace stipplot {

class UserError : public std::runtime_error {
 public:
  explicit UserError(const std::string& msg) : std::runtime_error(msg) {}
};

// Throws UserError("<name> must be ...") unless v is finite and within [lo, hi].
void require_range(const char* name, double v, double lo, double hi);
// Finite and >= 0.
void require_nonnegative(const char* name, double v);
// Finite and > 0.
void require_positive(const char* name, double v);

}  // namespace stipplot
