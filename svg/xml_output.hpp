#pragma once
// The two ways every SVG writer here emits a document through tinyxml2's streaming
// printer: into a string, or into a file that appears whole or not at all.
#include <tinyxml2.h>

#include <functional>
#include <string>

namespace stipplot {

using XmlBody = std::function<void(tinyxml2::XMLPrinter&)>;

std::string xml_to_string(const XmlBody& body);
// Throws UserError naming `path` when it cannot be written (the temporary is removed).
void xml_to_file_atomic(const std::string& path, const XmlBody& body);

}  // namespace stipplot
