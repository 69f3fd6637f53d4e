#pragma once
// A line the device rejected, an alarm, or a device that stopped working mid-job: the
// message names the line and the device's meaning; the journal has been synced first.
#include <string>

#include "util/error.hpp"

namespace stipplot::io {

class DeviceError : public UserError {
 public:
  DeviceError(const std::string& msg, long line, int code, bool alarm)
      : UserError(msg), line_(line), code_(code), alarm_(alarm) {}
  long line() const { return line_; }  // job line index, -1 when not known
  int code() const { return code_; }    // the device's error or alarm number
  bool alarm() const { return alarm_; }

 private:
  long line_;
  int code_;
  bool alarm_;
};

}  // namespace stipplot::io
