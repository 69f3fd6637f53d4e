#pragma once
// USB bulk transport through libusb, for plotters that enumerate as a USB printer or
// vendor device (no serial adapter): claims an interface, writes to its bulk-OUT
// endpoint and reads its bulk-IN endpoint where there is one.
#include <string>
#include <vector>

#include "drivers/transport/transport.hpp"

struct libusb_context;
struct libusb_device_handle;

namespace stipplot::io {

struct UsbDeviceInfo {
  int bus = 0, address = 0;
  int vid = 0, pid = 0;
  int device_class = 0;
  std::string manufacturer, product, serial;  // empty when the device cannot be opened
  bool has_bulk_out = false;
};

// USB devices libusb sees. `error` gets a reason when libusb itself is unavailable
// (no /dev/bus/usb in a container, ...); an empty list then is not "no devices".
std::vector<UsbDeviceInfo> list_usb_devices(std::string* error = nullptr);

// "usb:1a86:7523" or "usb:1a86:7523:2" (the third number picks the Nth match, from 0).
struct UsbSelector {
  int vid = -1, pid = -1, index = 0;
};
UsbSelector parse_usb_selector(const std::string& spec);  // throws UserError

class UsbBulk final : public Transport {
 public:
  // Throws TransportError(NotFound) "no such USB device" when nothing matches.
  explicit UsbBulk(const UsbSelector& sel);
  ~UsbBulk() override;
  void write(std::string_view bytes, Millis timeout) override;
  size_t read(char* buf, size_t n, Millis timeout) override;
  bool is_connected() const override { return handle_ != nullptr; }
  void close() override;
  std::string describe() const override;
  bool has_bulk_in() const { return ep_in_ != 0; }

 private:
  [[noreturn]] void fail(const char* what, int rc);
  UsbSelector sel_;
  libusb_context* ctx_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  int interface_ = -1;
  unsigned char ep_out_ = 0, ep_in_ = 0;
  bool reattach_kernel_ = false;
};

}  // namespace stipplot::io
