#pragma once
// The output plumbing the writers share: they emit command lines one at a time, so a
// driver can stream them to a device and a file writer can write them atomically.
#include <functional>
#include <string>
#include <string_view>

namespace stipplot {

// Receives one command line at a time, without a line terminator.
using LineSink = std::function<void(std::string_view)>;

// Writes the lines a generator produces to `path` atomically, each followed by
// `separator` ("\n", or "" for HPGL devices that want none).
void write_lines_atomic(const std::string& path, const std::function<void(const LineSink&)>& generate,
                        std::string_view separator = "\n");

}  // namespace stipplot
