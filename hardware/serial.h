// POSIX serial transport (termios, raw 8N1) with read timeouts and reconnection.
// Works on USB serial adapters and on pseudo-terminals (the emulator).
#pragma once
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace morphfem::hw {

// A device fault: error reply, timeout, disconnect, implausible measurement.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
class TimeoutError : public DeviceError {
 public:
  using DeviceError::DeviceError;
};
class DisconnectedError : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

class SerialPort {
 public:
  SerialPort(std::string path, int baud);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Opens and configures the port (raw, 8N1, no flow control). Throws DeviceError.
  void open();
  void close();
  bool is_open() const { return fd_ >= 0; }
  const std::string& path() const { return path_; }

  // Writes every byte or throws (DisconnectedError if the device went away).
  void write_all(const std::uint8_t* data, std::size_t n, double timeout_s);
  void write_all(const std::string& s, double timeout_s) {
    write_all(reinterpret_cast<const std::uint8_t*>(s.data()), s.size(), timeout_s);
  }
  void write_all(const std::vector<std::uint8_t>& v, double timeout_s) { write_all(v.data(), v.size(), timeout_s); }
  // Reads what is available, waiting up to timeout_s for the first byte.
  // Returns 0 on timeout; throws DisconnectedError on hang-up or I/O error.
  std::size_t read_some(std::uint8_t* buf, std::size_t n, double timeout_s);
  // Reads up to and including `terminator`; throws TimeoutError after timeout_s.
  std::string read_line(char terminator, double timeout_s, std::size_t max_len = 256);
  // Discards pending input (stale replies after a timeout).
  void drain_input();
  // Closes and retries open() every 50 ms until timeout_s. Returns true on success.
  bool reconnect(double timeout_s);

 private:
  std::string path_;
  int baud_;
  int fd_ = -1;
};

// termios speed constant for a baud rate; throws std::invalid_argument if unsupported.
unsigned baud_constant(int baud);

}  // namespace morphfem::hw
