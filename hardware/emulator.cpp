#include "hardware/emulator.h"

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <stdexcept>

#include "core/errors.h"

namespace morphfem::hw {

namespace {
double wall_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
}  // namespace

struct Emulator::Chan {
  int channel = -1;
  std::size_t device = 0;
  int address = 0;
  double p = 0, sp = 0;
  int mode = 0;  // 0 vent, 1 regulate, 2 hold
  bool ruptured = false, stuck = false;
  double stuck_u = 0, last_u = 0;
  double half_band_pa = 0;
  long commands = 0;
  double max_p = 0;
  double ruptured_at = -1, vented_at = -1;
  std::uint8_t regs[booth::kRegisters] = {};
};

struct Emulator::Device {
  DeviceSpec spec;
  int master = -1, slave_keepalive = -1;
  std::string pty_path, link;
  std::vector<std::uint8_t> rx;
  bool down = false;
  double return_at = -1;  // wall time the device reappears (-1: never)
  struct Pending {
    double due;
    std::vector<std::uint8_t> bytes;
  };
  std::deque<Pending> out;
};

EmulatorFault parse_fault(const std::string& spec, const std::string& where) {
  EmulatorFault f;
  auto at = spec.find('@');
  if (at == std::string::npos) throw InputError(where, "fault '" + spec + "' must look like kind@time[:arg]");
  std::string kind = spec.substr(0, at), rest = spec.substr(at + 1), arg;
  auto colon = rest.find(':');
  if (colon != std::string::npos) {
    arg = rest.substr(colon + 1);
    rest = rest.substr(0, colon);
  }
  static const std::map<std::string, EmulatorFault::Kind> kinds = {
      {"garble", EmulatorFault::garble},         {"drop", EmulatorFault::drop},
      {"silence", EmulatorFault::silence},       {"delay", EmulatorFault::delay},
      {"disconnect", EmulatorFault::disconnect}, {"stuck", EmulatorFault::stuck},
      {"rupture", EmulatorFault::rupture}};
  auto k = kinds.find(kind);
  if (k == kinds.end())
    throw InputError(where,
                     "unknown fault kind '" + kind + "' (garble, drop, silence, delay, disconnect, stuck, rupture)");
  f.kind = k->second;
  auto num = [&](const std::string& s, const char* what) {
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v) || v < 0)
      throw InputError(where, "fault '" + spec + "': bad " + what + " '" + s + "'");
    return v;
  };
  f.at_s = num(rest, "time");
  switch (f.kind) {
    case EmulatorFault::garble:
    case EmulatorFault::drop:
      f.arg = arg.empty() ? 1 : num(arg, "count");
      break;
    case EmulatorFault::silence:
      f.arg = arg.empty() ? -1 : num(arg, "duration");
      break;
    case EmulatorFault::delay:
      f.arg = num(arg, "delay in ms");
      break;
    case EmulatorFault::disconnect:
      f.arg = arg.empty() ? -1 : num(arg, "duration");
      break;
    case EmulatorFault::stuck:
    case EmulatorFault::rupture:
      f.channel = channel_index(arg);
      if (f.channel < 0) throw InputError(where, "fault '" + spec + "': unknown channel '" + arg + "'");
      break;
  }
  return f;
}

Emulator::Emulator(ChannelMap map, EmulatorConfig config)
    : map_(std::move(map)), cfg_(std::move(config)), rng_(cfg_.seed) {
  for (auto& d : map_.devices) {
    auto dev = std::make_unique<Device>();
    dev->spec = d;
    auto l = cfg_.links.find(d.name);
    if (l != cfg_.links.end()) dev->link = l->second;
    devices_.push_back(std::move(dev));
  }
  for (auto& c : map_.channels) {
    auto ch = std::make_unique<Chan>();
    ch->channel = c.channel;
    ch->address = c.address;
    for (std::size_t i = 0; i < devices_.size(); ++i)
      if (devices_[i]->spec.name == c.device) ch->device = i;
    chans_.push_back(std::move(ch));
  }
}

Emulator::~Emulator() { stop(); }

void Emulator::open_pty(Device& d) {
  int m = posix_openpt(O_RDWR | O_NOCTTY);
  if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0)
    throw std::runtime_error(std::string("cannot create a pseudo-terminal: ") + std::strerror(errno));
  char* name = ptsname(m);
  if (!name) throw std::runtime_error("ptsname failed");
  d.pty_path = name;
  termios tio{};
  tcgetattr(m, &tio);
  cfmakeraw(&tio);
  tcsetattr(m, TCSANOW, &tio);
  fcntl(m, F_SETFL, fcntl(m, F_GETFL) | O_NONBLOCK);
  fcntl(m, F_SETFD, FD_CLOEXEC);
  // Keep one slave descriptor open so the master never sees a hang-up while the
  // player reconnects; it is never read.
  d.slave_keepalive = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (d.slave_keepalive >= 0) {
    termios st{};
    tcgetattr(d.slave_keepalive, &st);
    cfmakeraw(&st);
    tcsetattr(d.slave_keepalive, TCSANOW, &st);
  }
  d.master = m;
  d.rx.clear();
  d.out.clear();
  d.down = false;
  if (!d.link.empty()) {
    std::string tmp = d.link + ".tmp";
    ::unlink(tmp.c_str());
    if (::symlink(name, tmp.c_str()) != 0 || ::rename(tmp.c_str(), d.link.c_str()) != 0)
      throw std::runtime_error("cannot create link " + d.link + ": " + std::strerror(errno));
  }
}

void Emulator::close_pty(Device& d) {
  if (!d.link.empty()) ::unlink(d.link.c_str());
  if (d.master >= 0) ::close(d.master);
  if (d.slave_keepalive >= 0) ::close(d.slave_keepalive);
  d.master = d.slave_keepalive = -1;
  d.down = true;
}

std::map<std::string, std::string> Emulator::start() {
  std::map<std::string, std::string> paths;
  for (auto& d : devices_) {
    open_pty(*d);
    paths[d->spec.name] = d->link.empty() ? d->pty_path : d->link;
  }
  last_wall_ = wall_s();
  stop_ = false;
  thread_ = std::thread([this] { loop(); });
  return paths;
}

void Emulator::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  for (auto& d : devices_)
    if (!d->down) close_pty(*d);
}

double Emulator::emulated_time() const {
  std::lock_guard<std::mutex> lock(mu_);
  return t_emu_;
}

std::vector<EmulatedChannelState> Emulator::snapshot() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<EmulatedChannelState> out;
  for (auto& c : chans_)
    out.push_back(
        {c->channel, c->p, c->sp, c->mode, c->ruptured, c->stuck, c->commands, c->max_p, c->ruptured_at, c->vented_at});
  return out;
}

EmulatedChannelState Emulator::channel(int ch) const {
  for (auto& s : snapshot())
    if (s.channel == ch) return s;
  return {};
}

bool Emulator::all_vented() const {
  for (auto& s : snapshot())
    if (!(s.mode == 0 || (s.mode == 1 && s.setpoint_pa == 0))) return false;
  return true;
}

void Emulator::step_physics(double dt) {
  const double h_max = 0.0005;
  int n = std::max(1, static_cast<int>(std::ceil(dt / h_max)));
  double h = dt / n;
  for (auto& cp : chans_) {
    Chan& c = *cp;
    bool bladder = c.channel < kNumBladders;
    for (int i = 0; i < n; ++i) {
      double dp = 0;
      if (c.mode == 1 || c.stuck) {
        double u;
        if (c.stuck) {
          u = c.stuck_u;
        } else {
          double e = c.sp - c.p;
          u = std::abs(e) <= c.half_band_pa ? 0.0 : std::clamp(e / cfg_.valve_band_pa, -1.0, 1.0);
        }
        c.last_u = u;
        if (cfg_.valve_fill_time_s > 0 && !c.stuck)
          dp = (c.sp - c.p) / cfg_.valve_fill_time_s;
        else
          dp = u > 0 ? u * (cfg_.supply_pa - c.p) / cfg_.tau_s : u * (c.p - cfg_.vacuum_pa) / cfg_.tau_s;
      } else if (c.mode == 0) {
        dp = -c.p / cfg_.vent_tau_s;
        c.last_u = 0;
      }
      if (c.ruptured) dp += -c.p / cfg_.leak_tau_s;
      // Exact-enough explicit step; the limits keep it inside the physical range.
      c.p = std::clamp(c.p + h * dp, cfg_.vacuum_pa, cfg_.supply_pa);
      c.max_p = std::max(c.max_p, c.p);
      if (!c.ruptured && c.p > (bladder ? cfg_.rupture_pa : cfg_.rupture_core_pa)) {
        c.ruptured = true;
        c.ruptured_at = fault_clock() + (i + 1) * h;  // t_emu_ advances after the loop
      }
    }
  }
  t_emu_ += dt;
}

double Emulator::measure(const Chan& c, Protocol p) {
  std::normal_distribution<double> noise(0.0, cfg_.noise_pa);
  double v = c.p + (cfg_.noise_pa > 0 ? noise(rng_) : 0.0);
  if (p == Protocol::alicat) return std::round(v / 10.0) * 10.0;
  booth::Sensor s{map_.devices[c.device].sensor_min_pa, map_.devices[c.device].sensor_max_pa};
  return s.pressure(s.counts(v));
}

void Emulator::send(Device& d, std::vector<std::uint8_t> bytes) {
  double rel = t_first_request_ < 0 ? 0 : t_emu_ - t_first_request_;
  (void)rel;
  if (silence_until_ != -1 && (silence_until_ < 0 || t_emu_ < silence_until_)) return;
  if (garble_left_ > 0 && !bytes.empty()) {
    --garble_left_;
    if (d.spec.protocol == Protocol::alicat) {
      // Corrupt the first number so that no parser can take it for a value.
      if (bytes.size() > 3)
        bytes[3] = '#';
      else
        bytes.insert(bytes.begin(), '#');
    } else {
      bytes.back() ^= 0x5a;  // CRC no longer matches
    }
  }
  if (drop_left_ > 0 && !bytes.empty()) {
    --drop_left_;
    bytes.pop_back();
  }
  d.out.push_back({wall_s() + delay_ms_ / 1000.0, std::move(bytes)});
}

void Emulator::handle_alicat(Device& d, const std::string& raw) {
  std::string line = raw;
  while (!line.empty() && (line.back() == '\r' || line.back() == '\n')) line.pop_back();
  while (!line.empty() && line.front() == '\n') line.erase(line.begin());
  if (line.empty()) return;
  char id = line[0];
  Chan* c = nullptr;
  for (auto& cp : chans_)
    if (&*devices_[cp->device] == &d && cp->address == id) c = &*cp;
  if (!c) return;  // no such unit on this line: silence
  std::string rest = line.substr(1);
  if (rest.empty()) {
    // poll
  } else if (rest[0] == 'S') {
    std::string num = rest.substr(1);
    while (!num.empty() && num.front() == ' ') num.erase(num.begin());
    char* end = nullptr;
    double kpa = std::strtod(num.c_str(), &end);
    if (num.empty() || end != num.c_str() + num.size() || !std::isfinite(kpa)) {
      send(d, {'?', '\r'});
      return;
    }
    ++c->commands;
    if (!c->stuck) {
      c->sp = kpa * 1000.0;
      c->mode = 1;
    }
  } else {
    return;  // unsupported command: silence
  }
  AlicatFrame f;
  f.id = id;
  f.pressure_pa = measure(*c, Protocol::alicat);
  f.setpoint_pa = c->sp;
  if (c->last_u < -0.01)
    f.status.push_back("EXH");
  else if (c->last_u == 0)
    f.status.push_back("HLD");
  if (c->p > cfg_.supply_pa * 0.99) f.status.push_back("OPR");
  std::string s = format_alicat_frame(f);
  send(d, std::vector<std::uint8_t>(s.begin(), s.end()));
}

void Emulator::handle_booth(Device& d, const booth::Frame& f) {
  Chan* c = nullptr;
  for (auto& cp : chans_)
    if (&*devices_[cp->device] == &d && cp->address == f.addr) c = &*cp;
  if (!c) {
    send(d, booth::reply_frame(booth::kStatusNack, f.addr, {}));
    return;
  }
  booth::Sensor sensor{d.spec.sensor_min_pa, d.spec.sensor_max_pa};
  if (f.cmd_or_status == booth::kCmdWrite) {
    if (f.reg + f.data.size() > booth::kRegisters) {
      send(d, booth::reply_frame(booth::kStatusBadRange, f.addr, {}));
      return;
    }
    ++c->commands;
    for (std::size_t i = 0; i < f.data.size(); ++i)
      if (f.reg + i != booth::kRegPressureHi && f.reg + i != booth::kRegPressureLo) c->regs[f.reg + i] = f.data[i];
    if (!c->stuck) {
      c->sp = sensor.pressure(booth::get_counts(c->regs[booth::kRegSetpointHi], c->regs[booth::kRegSetpointLo]));
      c->half_band_pa = c->regs[booth::kRegHalfBand] * sensor.resolution_pa();
      std::uint8_t st = c->regs[booth::kRegDesiredState];
      if (st == booth::kStateVent) {
        c->mode = 0;
        if (c->vented_at < 0) c->vented_at = fault_clock();
      } else if (c->regs[booth::kRegMode] == 0 || st == booth::kStateHold)
        c->mode = 2;
      else
        c->mode = 1;
    }
    send(d, booth::reply_frame(booth::kStatusAck, f.addr, {}));
  } else if (f.cmd_or_status == booth::kCmdRead) {
    int len = f.data.empty() ? 0 : f.data[0];
    int reg = f.reg;
    if (len == 0) {
      if (c->regs[booth::kRegOnlyPressure]) {
        reg = booth::kRegPressureHi;
        len = 2;
      } else {
        reg = 0;
        len = booth::kRegisters;
      }
    }
    if (reg + len > booth::kRegisters) {
      send(d, booth::reply_frame(booth::kStatusBadRange, f.addr, {}));
      return;
    }
    booth::put_counts(sensor.counts(measure(*c, Protocol::booth)), c->regs[booth::kRegPressureHi],
                      c->regs[booth::kRegPressureLo]);
    send(d,
         booth::reply_frame(booth::kStatusAck, f.addr, std::vector<std::uint8_t>(c->regs + reg, c->regs + reg + len)));
  } else {
    send(d, booth::reply_frame(booth::kStatusBadCommand, f.addr, {}));
  }
}

// Writes the replies that are due (all of them unless a `delay` fault holds them).
void Emulator::flush_replies(Device& d, double now_wall) {
  while (!d.out.empty() && d.out.front().due <= now_wall) {
    auto& b = d.out.front().bytes;
    if (!b.empty()) {
      ssize_t w = ::write(d.master, b.data(), b.size());
      if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    }
    d.out.pop_front();
  }
}

void Emulator::serve(Device& d, double now_wall) {
  flush_replies(d, now_wall);
  std::uint8_t buf[512];
  for (;;) {
    ssize_t r = ::read(d.master, buf, sizeof buf);
    if (r <= 0) break;
    d.rx.insert(d.rx.end(), buf, buf + r);
  }
  // Frames: a Booth request starts with A5; anything else is an ASCII line.
  while (!d.rx.empty()) {
    if (d.rx[0] == booth::kRequestSync) {
      booth::Frame f;
      std::size_t used = 0;
      std::string err;
      auto res = booth::parse_request(d.rx.data(), d.rx.size(), f, used, err);
      if (res == booth::Parse::need_more) break;
      if (t_first_request_ < 0) t_first_request_ = t_emu_;
      ++requests_;
      if (res == booth::Parse::ok)
        handle_booth(d, f);
      else if (used > 1 && d.rx.size() >= 3)
        send(d, booth::reply_frame(booth::kStatusBadCrc, d.rx[2], {}));
      d.rx.erase(d.rx.begin(), d.rx.begin() + std::max<std::size_t>(1, used));
    } else {
      auto cr = std::find(d.rx.begin(), d.rx.end(), '\r');
      if (cr == d.rx.end()) {
        if (d.rx.size() > 256) d.rx.clear();
        break;
      }
      std::string line(d.rx.begin(), cr + 1);
      d.rx.erase(d.rx.begin(), cr + 1);
      if (t_first_request_ < 0) t_first_request_ = t_emu_;
      ++requests_;
      handle_alicat(d, line);
    }
  }
  flush_replies(d, wall_s());  // answer within this loop turn (replies are due from when they were made)
}

void Emulator::fire_faults(double now_wall) {
  if (t_first_request_ < 0) return;
  double rel = t_emu_ - t_first_request_;
  for (auto& f : cfg_.faults) {
    if (f.fired || rel < f.at_s) continue;
    f.fired = true;
    switch (f.kind) {
      case EmulatorFault::garble:
        garble_left_ += static_cast<int>(f.arg);
        break;
      case EmulatorFault::drop:
        drop_left_ += static_cast<int>(f.arg);
        break;
      case EmulatorFault::silence:
        silence_until_ = f.arg < 0 ? -2 : t_emu_ + f.arg;
        break;
      case EmulatorFault::delay:
        delay_ms_ = f.arg;
        break;
      case EmulatorFault::disconnect:
        for (auto& d : devices_) {
          close_pty(*d);
          d->return_at = f.arg < 0 ? -1 : now_wall + f.arg;
        }
        break;
      case EmulatorFault::stuck:
        for (auto& c : chans_)
          if (c->channel == f.channel) {
            c->stuck = true;
            c->stuck_u = 0;  // stuck closed: the channel holds its pressure
          }
        break;
      case EmulatorFault::rupture:
        for (auto& c : chans_)
          if (c->channel == f.channel && !c->ruptured) {
            c->ruptured = true;
            c->ruptured_at = rel;
          }
        break;
    }
  }
}

void Emulator::loop() {
  while (!stop_) {
    std::vector<pollfd> fds;
    for (auto& d : devices_)
      if (!d->down) fds.push_back({d->master, POLLIN, 0});
    if (fds.empty())
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    else
      ::poll(fds.data(), fds.size(), 2);
    std::lock_guard<std::mutex> lock(mu_);
    double now = wall_s();
    double dt = (now - last_wall_) * cfg_.time_scale;
    last_wall_ = now;
    // Emulated time stays time_scale x wall, the player's clock, even after the
    // thread was starved on a loaded machine (a 1 s cap here once let the valves
    // fall behind the player's schedule). 60 s only bounds the work after a pause.
    if (dt > 0) step_physics(std::min(dt, 60.0));
    fire_faults(now);
    for (auto& d : devices_) {
      if (d->down) {
        if (d->return_at >= 0 && now >= d->return_at) {
          try {
            open_pty(*d);
          } catch (const std::exception&) {
            d->return_at = now + 0.05;
          }
        }
        continue;
      }
      serve(*d, now);
    }
  }
}

}  // namespace morphfem::hw
