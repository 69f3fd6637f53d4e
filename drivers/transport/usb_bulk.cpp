#include "drivers/transport/usb_bulk.hpp"

#include <libusb.h>

#include <cstdio>
#include <cstdlib>

namespace stipplot::io {

namespace {

std::string hex4(int v) {
  char b[8];
  std::snprintf(b, sizeof b, "%04x", v & 0xffff);
  return b;
}

std::string descriptor_string(libusb_device_handle* h, uint8_t index) {
  if (!h || index == 0) return {};
  unsigned char buf[256];
  int n = libusb_get_string_descriptor_ascii(h, index, buf, sizeof buf);
  return n > 0 ? std::string(reinterpret_cast<char*>(buf), static_cast<size_t>(n)) : std::string();
}

struct BulkEndpoints {
  int interface = -1;
  unsigned char out = 0, in = 0;
};

// First interface with a bulk-OUT endpoint (and its bulk-IN, if any).
BulkEndpoints find_bulk(libusb_device* dev) {
  BulkEndpoints b;
  libusb_config_descriptor* cfg = nullptr;
  if (libusb_get_active_config_descriptor(dev, &cfg) != 0 && libusb_get_config_descriptor(dev, 0, &cfg) != 0)
    return b;
  for (int i = 0; i < cfg->bNumInterfaces && b.interface < 0; ++i) {
    const libusb_interface& itf = cfg->interface[i];
    for (int a = 0; a < itf.num_altsetting && b.interface < 0; ++a) {
      const libusb_interface_descriptor& d = itf.altsetting[a];
      unsigned char out = 0, in = 0;
      for (int e = 0; e < d.bNumEndpoints; ++e) {
        const libusb_endpoint_descriptor& ep = d.endpoint[e];
        if ((ep.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK) != LIBUSB_TRANSFER_TYPE_BULK) continue;
        if (ep.bEndpointAddress & LIBUSB_ENDPOINT_IN) {
          if (!in) in = ep.bEndpointAddress;
        } else if (!out) {
          out = ep.bEndpointAddress;
        }
      }
      if (out) b = {d.bInterfaceNumber, out, in};
    }
  }
  libusb_free_config_descriptor(cfg);
  return b;
}

}  // namespace

std::vector<UsbDeviceInfo> list_usb_devices(std::string* error) {
  std::vector<UsbDeviceInfo> out;
  libusb_context* ctx = nullptr;
  int rc = libusb_init(&ctx);
  if (rc != 0) {
    if (error) *error = std::string("libusb unavailable: ") + libusb_strerror(static_cast<libusb_error>(rc));
    return out;
  }
  libusb_device** list = nullptr;
  ssize_t n = libusb_get_device_list(ctx, &list);
  if (n < 0 && error) *error = std::string("cannot list USB devices: ") + libusb_strerror(static_cast<libusb_error>(n));
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device* dev = list[i];
    libusb_device_descriptor dd{};
    if (libusb_get_device_descriptor(dev, &dd) != 0) continue;
    if (dd.bDeviceClass == LIBUSB_CLASS_HUB) continue;  // root hubs and hubs are not plotters
    UsbDeviceInfo info;
    info.bus = libusb_get_bus_number(dev);
    info.address = libusb_get_device_address(dev);
    info.vid = dd.idVendor;
    info.pid = dd.idProduct;
    info.device_class = dd.bDeviceClass;
    info.has_bulk_out = find_bulk(dev).interface >= 0;
    libusb_device_handle* h = nullptr;
    if (libusb_open(dev, &h) == 0) {
      info.manufacturer = descriptor_string(h, dd.iManufacturer);
      info.product = descriptor_string(h, dd.iProduct);
      info.serial = descriptor_string(h, dd.iSerialNumber);
      libusb_close(h);
    }
    out.push_back(std::move(info));
  }
  if (list) libusb_free_device_list(list, 1);
  libusb_exit(ctx);
  return out;
}

UsbSelector parse_usb_selector(const std::string& spec) {
  std::string s = spec.rfind("usb:", 0) == 0 ? spec.substr(4) : spec;
  UsbSelector sel;
  unsigned vid = 0, pid = 0;
  int idx = 0;
  int got = std::sscanf(s.c_str(), "%x:%x:%d", &vid, &pid, &idx);
  if (got < 2 || vid > 0xffff || pid > 0xffff || idx < 0)
    throw UserError("USB port must look like usb:VID:PID[:N] with hex ids (e.g. usb:0403:6001), got '" + spec + "'");
  sel.vid = static_cast<int>(vid);
  sel.pid = static_cast<int>(pid);
  sel.index = got == 3 ? idx : 0;
  return sel;
}

UsbBulk::UsbBulk(const UsbSelector& sel) : sel_(sel) {
  std::string id = hex4(sel.vid) + ":" + hex4(sel.pid);
  int rc = libusb_init(&ctx_);
  if (rc != 0) {
    ctx_ = nullptr;
    throw TransportError(TransportError::Kind::NotFound, "no such USB device " + id + " (libusb unavailable: " +
                                                             libusb_strerror(static_cast<libusb_error>(rc)) + ")");
  }
  libusb_device** list = nullptr;
  ssize_t n = libusb_get_device_list(ctx_, &list);
  libusb_device* found = nullptr;
  int seen = 0;
  for (ssize_t i = 0; i < n && !found; ++i) {
    libusb_device_descriptor dd{};
    if (libusb_get_device_descriptor(list[i], &dd) != 0) continue;
    if (dd.idVendor == sel.vid && dd.idProduct == sel.pid && seen++ == sel.index) found = list[i];
  }
  BulkEndpoints eps;
  if (found) {
    eps = find_bulk(found);
    rc = libusb_open(found, &handle_);
  }
  if (list) libusb_free_device_list(list, 1);
  auto bail = [&](TransportError::Kind k, const std::string& msg) {
    close();
    throw TransportError(k, msg);
  };
  if (!found) bail(TransportError::Kind::NotFound, "no such USB device " + id + " (run `stipplot devices`)");
  if (eps.interface < 0) bail(TransportError::Kind::Io, "USB device " + id + " has no bulk-OUT endpoint");
  if (rc != 0 || !handle_) {
    handle_ = nullptr;
    bail(TransportError::Kind::Io, "cannot open USB device " + id + ": " + libusb_strerror(static_cast<libusb_error>(rc)) +
                                       " (permissions? add a udev rule for it)");
  }
  if (libusb_kernel_driver_active(handle_, eps.interface) == 1) {
    if (libusb_detach_kernel_driver(handle_, eps.interface) == 0) reattach_kernel_ = true;
  }
  rc = libusb_claim_interface(handle_, eps.interface);
  if (rc != 0)
    bail(TransportError::Kind::Io, "cannot claim interface " + std::to_string(eps.interface) + " of USB device " + id +
                                       ": " + libusb_strerror(static_cast<libusb_error>(rc)));
  interface_ = eps.interface;
  ep_out_ = eps.out;
  ep_in_ = eps.in;
}

UsbBulk::~UsbBulk() { close(); }

void UsbBulk::close() {
  if (handle_) {
    if (interface_ >= 0) {
      libusb_release_interface(handle_, interface_);
      if (reattach_kernel_) libusb_attach_kernel_driver(handle_, interface_);
    }
    libusb_close(handle_);
    handle_ = nullptr;
  }
  interface_ = -1;
  if (ctx_) libusb_exit(ctx_);
  ctx_ = nullptr;
}

std::string UsbBulk::describe() const { return "usb " + hex4(sel_.vid) + ":" + hex4(sel_.pid); }

void UsbBulk::fail(const char* what, int rc) {
  std::string id = describe();
  if (rc == LIBUSB_ERROR_NO_DEVICE || rc == LIBUSB_ERROR_IO || rc == LIBUSB_ERROR_PIPE) {
    close();
    throw TransportError(TransportError::Kind::Disconnected,
                         id + " disconnected during " + what + " (" + libusb_strerror(static_cast<libusb_error>(rc)) + ")");
  }
  throw TransportError(TransportError::Kind::Io, id + " " + what + " failed: " + libusb_strerror(static_cast<libusb_error>(rc)));
}

void UsbBulk::write(std::string_view bytes, Millis timeout) {
  if (!handle_) throw TransportError(TransportError::Kind::Disconnected, describe() + " is closed");
  size_t off = 0;
  while (off < bytes.size()) {
    int sent = 0;
    int len = static_cast<int>(std::min<size_t>(bytes.size() - off, 4096));
    int rc = libusb_bulk_transfer(handle_, ep_out_,
                                  reinterpret_cast<unsigned char*>(const_cast<char*>(bytes.data() + off)), len, &sent,
                                  static_cast<unsigned>(timeout.count()));
    off += static_cast<size_t>(sent);
    if (rc == LIBUSB_ERROR_TIMEOUT)
      throw TransportError(TransportError::Kind::Timeout,
                           describe() + " did not accept data for " + std::to_string(timeout.count()) + " ms");
    if (rc != 0) fail("write", rc);
  }
}

size_t UsbBulk::read(char* buf, size_t n, Millis timeout) {
  if (!handle_) throw TransportError(TransportError::Kind::Disconnected, describe() + " is closed");
  if (!ep_in_) return 0;  // write-only device: silence
  int got = 0;
  // libusb reads a timeout of 0 as "forever"; 1 ms is the shortest wait it has.
  unsigned t = static_cast<unsigned>(std::max<long>(1, timeout.count()));
  int rc = libusb_bulk_transfer(handle_, ep_in_, reinterpret_cast<unsigned char*>(buf), static_cast<int>(n), &got, t);
  if (rc == LIBUSB_ERROR_TIMEOUT) return static_cast<size_t>(got);
  if (rc != 0) fail("read", rc);
  return static_cast<size_t>(got);
}

}  // namespace stipplot::io
