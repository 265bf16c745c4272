#include "hardware/serial.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

namespace morphfem::hw {

namespace {
double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
}  // namespace

unsigned baud_constant(int baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    default:
      throw std::invalid_argument("unsupported baud rate " + std::to_string(baud));
  }
}

SerialPort::SerialPort(std::string path, int baud) : path_(std::move(path)), baud_(baud) {}

SerialPort::~SerialPort() { close(); }

void SerialPort::open() {
  close();
  int fd = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw DisconnectedError("cannot open serial port " + path_ + ": " + std::strerror(errno));
  termios tio{};
  if (tcgetattr(fd, &tio) != 0) {
    int e = errno;
    ::close(fd);
    throw DeviceError(path_ + " is not a serial port: " + std::strerror(e));
  }
  cfmakeraw(&tio);
  tio.c_cflag &= ~(CSTOPB | PARENB | CRTSCTS | CSIZE);
  tio.c_cflag |= CS8 | CLOCAL | CREAD;
  tio.c_iflag &= ~(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  speed_t sp = baud_constant(baud_);
  cfsetispeed(&tio, sp);
  cfsetospeed(&tio, sp);
  if (tcsetattr(fd, TCSANOW, &tio) != 0) {
    int e = errno;
    ::close(fd);
    throw DeviceError("cannot configure " + path_ + ": " + std::strerror(e));
  }
  tcflush(fd, TCIOFLUSH);
  fd_ = fd;
}

void SerialPort::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void SerialPort::write_all(const std::uint8_t* data, std::size_t n, double timeout_s) {
  if (fd_ < 0) throw DisconnectedError(path_ + " is not open");
  double deadline = now_s() + timeout_s;
  std::size_t done = 0;
  while (done < n) {
    ssize_t w = ::write(fd_, data + done, n - done);
    if (w > 0) {
      done += static_cast<std::size_t>(w);
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && errno != EAGAIN && errno != EWOULDBLOCK)
      throw DisconnectedError("write to " + path_ + " failed: " + std::strerror(errno));
    double left = deadline - now_s();
    if (left <= 0) throw TimeoutError("write to " + path_ + " timed out");
    pollfd p{fd_, POLLOUT, 0};
    int r = ::poll(&p, 1, static_cast<int>(left * 1000) + 1);
    if (r > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL))) throw DisconnectedError(path_ + " hung up");
  }
}

std::size_t SerialPort::read_some(std::uint8_t* buf, std::size_t n, double timeout_s) {
  if (fd_ < 0) throw DisconnectedError(path_ + " is not open");
  // A raw tty with VMIN = VTIME = 0 returns 0 from read() when no data is
  // waiting, so end of file cannot be told from "nothing yet" by read() alone:
  // poll() reports the hang-up.
  double deadline = now_s() + timeout_s;
  for (;;) {
    double left = deadline - now_s();
    pollfd p{fd_, POLLIN, 0};
    int pr = ::poll(&p, 1, left > 0 ? static_cast<int>(left * 1000) + 1 : 0);
    if (pr < 0) {
      if (errno == EINTR) continue;
      throw DisconnectedError("poll on " + path_ + " failed: " + std::strerror(errno));
    }
    if (pr > 0) {
      if (p.revents & POLLIN) {
        ssize_t r = ::read(fd_, buf, n);
        if (r > 0) return static_cast<std::size_t>(r);
        if (r < 0 && errno != EINTR && errno != EAGAIN && errno != EWOULDBLOCK)
          throw DisconnectedError("read from " + path_ + " failed: " + std::strerror(errno));
      }
      if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) throw DisconnectedError(path_ + " hung up (device disconnected)");
    }
    if (now_s() >= deadline) return 0;
  }
}

std::string SerialPort::read_line(char terminator, double timeout_s, std::size_t max_len) {
  std::string line;
  double deadline = now_s() + timeout_s;
  std::uint8_t c;
  while (line.size() < max_len) {
    double left = deadline - now_s();
    if (left <= 0) break;
    if (read_some(&c, 1, left) == 0) break;
    line += static_cast<char>(c);
    if (static_cast<char>(c) == terminator) return line;
  }
  if (line.size() >= max_len) return line;  // caller rejects it as malformed
  throw TimeoutError("no complete reply within " + std::to_string(static_cast<int>(timeout_s * 1000)) + " ms on " +
                     path_ + (line.empty() ? " (silence)" : " (got a partial frame)"));
}

void SerialPort::drain_input() {
  if (fd_ < 0) return;
  std::uint8_t buf[256];
  for (int i = 0; i < 64; ++i) {
    ssize_t r = ::read(fd_, buf, sizeof buf);
    if (r <= 0) break;
  }
}

bool SerialPort::reconnect(double timeout_s) {
  close();
  double deadline = now_s() + timeout_s;
  for (;;) {
    try {
      open();
      return true;
    } catch (const DeviceError&) {
    }
    if (now_s() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

}  // namespace morphfem::hw
