// IoBackend: where the I/O image comes from and goes to (a plant model, Modbus devices,
// GPIO lines). The runtime owns the loop; a backend only exchanges image bytes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace plcfi::rt {

// Contract: called from the scan thread only. read() fills the input area buffer as the
// devices deliver it; write() sends the output area buffer. Neither may block beyond the
// cycle's deadline. On failure they return false and fill last_error(); the runtime keeps
// the last good inputs. `dt_ns` is the time that passes until the next read (the base
// tick): a simulated plant advances its physics by that much in write().
class IoBackend {
 public:
  virtual ~IoBackend() = default;
  virtual const std::string& name() const = 0;
  // Bytes of the %I / %Q areas this backend reads or writes (from the area start).
  virtual uint32_t input_extent() const = 0;
  virtual uint32_t output_extent() const = 0;
  virtual bool read(uint8_t* inputs, int64_t now_ns) = 0;
  virtual bool write(const uint8_t* outputs, int64_t now_ns, int64_t dt_ns) = 0;
  // The safe state, written on the way out (or before a restart): no link fault holds it
  // back, and a backend whose write can be lost (a reply late on a loaded bench, a
  // dropped connection) reconnects at once and repeats it. False when it could not be
  // delivered (last_error() says why).
  virtual bool write_final(const uint8_t* outputs, int64_t now_ns) { return write(outputs, now_ns, 0); }
  // Back to the initial state (a simulated plant resets its physics; real I/O: nothing).
  virtual void reset(uint64_t seed) = 0;
  virtual const std::string& last_error() const = 0;
  // Exchanges that failed or had to be repeated since the backend was made (a lost or
  // late reply, a broken link): the communication-error indicator of test scripts.
  // Backends that cannot fail (a simulated plant) count none.
  virtual uint64_t failed_exchanges() const { return 0; }
  // The devices whose link a test script may break (FAULT LINK device), by name.
  virtual std::vector<std::string> link_devices() const { return {}; }
  // Breaks the link to `device` during [from_ns, from_ns + duration_ns) of the scan clock:
  // its requests are lost (counted in failed_exchanges), its inputs keep their last good
  // values, its outputs are not delivered and its status bit reads FALSE. False when the
  // backend has no such device.
  virtual bool break_link(const std::string& device, int64_t from_ns, int64_t duration_ns) { return false; }
};

}  // namespace plcfi::rt
