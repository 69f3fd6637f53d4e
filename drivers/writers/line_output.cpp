#include "drivers/writers/line_output.hpp"

#include <cstdio>
#include <memory>

#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot {

void write_lines_atomic(const std::string& path, const std::function<void(const LineSink&)>& generate,
                        std::string_view separator) {
  AtomicFile out(path);
  {
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(out.temp_path().c_str(), "wb"), &std::fclose);
    if (!f) throw UserError("cannot write " + path);
    FILE* fp = f.get();
    // Millions of short lines: a large buffer, and no stream lock taken for each (only this
    // thread writes the file).
    std::setvbuf(fp, nullptr, _IOFBF, size_t{1} << 20);
    generate([fp, separator](std::string_view line) {
      fwrite_unlocked(line.data(), 1, line.size(), fp);
      if (!separator.empty()) fwrite_unlocked(separator.data(), 1, separator.size(), fp);
    });
    if (std::ferror(fp) || std::fflush(fp) != 0) throw UserError("cannot write " + path + " (disk full?)");
  }
  out.commit();
}

}  // namespace stipplot
