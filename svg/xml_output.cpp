#include "svg/xml_output.hpp"

#include <cstdio>
#include <memory>

#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot {

std::string xml_to_string(const XmlBody& body) {
  tinyxml2::XMLPrinter p;
  body(p);
  return std::string(p.CStr(), static_cast<size_t>(p.CStrSize() > 0 ? p.CStrSize() - 1 : 0));
}

void xml_to_file_atomic(const std::string& path, const XmlBody& body) {
  AtomicFile out(path);
  {
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(out.temp_path().c_str(), "wb"), &std::fclose);
    if (!f) throw UserError("cannot write " + path);
    tinyxml2::XMLPrinter p(f.get());
    body(p);
    if (std::ferror(f.get()) || std::fflush(f.get()) != 0) throw UserError("cannot write " + path + " (disk full?)");
  }
  out.commit();
}

}  // namespace stipplot
