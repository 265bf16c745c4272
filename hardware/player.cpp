#include "hardware/player.h"

#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>

#include "core/errors.h"
#include "hardware/protocols.h"
#include "hardware/serial.h"

namespace morphfem::hw {

namespace {

std::atomic<int> g_stop_signal{0};

extern "C" void on_stop_signal(int sig) { g_stop_signal.store(sig); }

double wall_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string kpa(double pa) {
  char b[32];
  if (!std::isfinite(pa)) return "--";
  std::snprintf(b, sizeof b, "%.1f", pa / 1000.0);
  return b;
}

// One serial line shared by the devices mapped to the same port.
struct Line {
  std::string path;
  int baud = 0;
  std::unique_ptr<SerialPort> port;
};

// One regulator channel with its protocol.
struct Regulator {
  ChannelSpec spec;
  DeviceSpec dev;
  Line* line = nullptr;
  double sent = kNaN;  // last setpoint acknowledged by the device

  std::string label() const {
    std::string a =
        dev.protocol == Protocol::alicat ? std::string(1, char(spec.address)) : std::to_string(spec.address);
    return channel_name(spec.channel) + " (" + dev.name + " " + protocol_name(dev.protocol) + " address " + a + ")";
  }

  // --- Alicat ---
  AlicatFrame alicat_exchange(const std::string& cmd, double timeout) {
    SerialPort& p = *line->port;
    p.drain_input();
    p.write_all(cmd, timeout);
    std::string reply = p.read_line('\r', timeout);
    AlicatReply r = parse_alicat_reply(reply, char(spec.address));
    if (r.status == ReplyStatus::rejected)
      throw DeviceError(label() + " rejected the command '" + escape_ascii(cmd) + "' (reply '?')");
    if (r.status != ReplyStatus::ok)
      throw DeviceError("garbled reply from " + label() + ": " + r.error + " in '" + escape_ascii(reply) + "'");
    return r.frame;
  }

  // --- Booth ---
  booth::Frame booth_exchange(const std::vector<std::uint8_t>& req, double timeout) {
    SerialPort& p = *line->port;
    p.drain_input();
    p.write_all(req, timeout);
    std::vector<std::uint8_t> buf;
    double deadline = wall_s() + timeout;
    for (;;) {
      booth::Frame f;
      std::size_t used = 0;
      std::string err;
      auto res = booth::parse_reply(buf.data(), buf.size(), f, used, err);
      if (res == booth::Parse::ok) {
        if (f.addr != spec.address)
          throw DeviceError("garbled reply from " + label() + ": reply names address " + std::to_string(f.addr));
        if (f.cmd_or_status != booth::kStatusAck)
          throw DeviceError(label() + " answered with error status " + std::to_string(f.cmd_or_status) +
                            (f.cmd_or_status == booth::kStatusNack ? " (no regulator at this address)" : ""));
        return f;
      }
      if (res == booth::Parse::bad)
        throw DeviceError("garbled reply from " + label() + ": " + err + " in [" + hex_bytes(buf) + "]");
      double left = deadline - wall_s();
      std::uint8_t tmp[64];
      std::size_t n = left > 0 ? p.read_some(tmp, sizeof tmp, left) : 0;
      if (n == 0)
        throw TimeoutError("no complete reply from " + label() + " within " + std::to_string(int(timeout * 1000)) +
                           " ms" + (buf.empty() ? " (silence)" : " (partial frame [" + hex_bytes(buf) + "])"));
      buf.insert(buf.end(), tmp, tmp + n);
      if (buf.size() > 64) throw DeviceError("garbled reply from " + label() + ": overlong frame");
    }
  }

  booth::Sensor sensor() const { return {dev.sensor_min_pa, dev.sensor_max_pa}; }

  std::vector<std::uint8_t> booth_setpoint_request(double pa, std::uint8_t state) const {
    std::uint8_t hi, lo;
    booth::put_counts(sensor().counts(pa), hi, lo);
    return booth::write_request(spec.address, booth::kRegSetpointHi, {hi, lo, state});
  }

  std::vector<std::uint8_t> booth_init_request() const {
    int hb = static_cast<int>(std::lround(dev.half_band_pa / sensor().resolution_pa()));
    return booth::write_request(spec.address, booth::kRegHalfBand,
                                {static_cast<std::uint8_t>(std::clamp(hb, 0, 255)), 1, 1});
  }

  // The bytes a command would put on the wire (dry run and logs).
  std::string wire_command(double pa) const {
    if (dev.protocol == Protocol::alicat) return escape_ascii(alicat_setpoint(char(spec.address), pa));
    return hex_bytes(booth_setpoint_request(pa, booth::kStateRegulate));
  }

  void init(double timeout) {
    sent = kNaN;
    if (dev.protocol == Protocol::alicat)
      alicat_exchange(alicat_poll(char(spec.address)), timeout);
    else
      booth_exchange(booth_init_request(), timeout);
  }

  // Sends a setpoint; returns the measured pressure.
  double command(double pa, double timeout) {
    if (dev.protocol == Protocol::alicat) {
      AlicatFrame f = alicat_exchange(alicat_setpoint(char(spec.address), pa), timeout);
      sent = pa;
      return f.pressure_pa;
    }
    booth_exchange(booth_setpoint_request(pa, booth::kStateRegulate), timeout);
    sent = pa;
    return poll(timeout);
  }

  double poll(double timeout) {
    if (dev.protocol == Protocol::alicat) return alicat_exchange(alicat_poll(char(spec.address)), timeout).pressure_pa;
    booth::Frame f = booth_exchange(booth::read_request(spec.address, 0, 0), timeout);
    if (f.data.size() != 2) throw DeviceError("garbled reply from " + label() + ": expected 2 pressure bytes");
    return sensor().pressure(booth::get_counts(f.data[0], f.data[1]));
  }

  void vent(double timeout) {
    if (dev.protocol == Protocol::alicat) {
      alicat_exchange(alicat_setpoint(char(spec.address), 0.0), timeout);
    } else {
      booth_exchange(booth_setpoint_request(0.0, booth::kStateVent), timeout);
    }
    sent = 0;
  }
};

class CsvLog {
 public:
  CsvLog(const std::string& path, const std::vector<int>& channels) : channels_(channels) {
    if (path.empty()) return;
    f_ = std::fopen(path.c_str(), "w");
    if (!f_) throw InputError(path, "cannot create the log file");
  }
  ~CsvLog() { close(); }
  bool open() const { return f_ != nullptr; }
  void meta(const std::string& key, const std::string& value) {
    if (f_) std::fprintf(f_, "# %s: %s\n", key.c_str(), value.c_str());
  }
  void header() {
    if (!f_) return;
    std::fprintf(f_, "t_s,kind,column");
    for (int c : channels_) std::fprintf(f_, ",cmd_%s", channel_name(c).c_str());
    for (int c : channels_) std::fprintf(f_, ",meas_%s", channel_name(c).c_str());
    std::fprintf(f_, ",message\n");
    flush();
  }
  void sample(double t, int column, const std::vector<double>& cmd, const std::vector<double>& meas) {
    if (!f_) return;
    std::fprintf(f_, "%.4f,sample,%d", t, column);
    for (double v : cmd) std::isfinite(v) ? (void)std::fprintf(f_, ",%.1f", v) : (void)std::fputc(',', f_);
    for (double v : meas) std::isfinite(v) ? (void)std::fprintf(f_, ",%.1f", v) : (void)std::fputc(',', f_);
    std::fprintf(f_, ",\n");
    if (wall_s() - last_flush_ >= 0.5) flush();
  }
  void event(double t, int column, const std::string& kind, std::string msg) {
    if (!f_) return;
    for (char& c : msg)
      if (c == ',' || c == '\n' || c == '\r') c = ';';
    std::fprintf(f_, "%.4f,%s,%d", t, kind.c_str(), column);
    for (std::size_t i = 0; i < 2 * channels_.size(); ++i) std::fputc(',', f_);
    std::fprintf(f_, ",%s\n", msg.c_str());
    flush();
  }
  void flush() {
    if (f_) std::fflush(f_);
    last_flush_ = wall_s();
  }
  void close() {
    if (!f_) return;
    std::fflush(f_);
    fsync(fileno(f_));
    std::fclose(f_);
    f_ = nullptr;
  }

 private:
  std::vector<int> channels_;
  std::FILE* f_ = nullptr;
  double last_flush_ = 0;
};

struct SignalGuard {
  bool active;
  struct sigaction old_int {
  }, old_term{};
  explicit SignalGuard(bool on) : active(on) {
    g_stop_signal = 0;
    if (!active) return;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
  }
  ~SignalGuard() {
    if (!active) return;
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  }
};

}  // namespace

void request_stop(int signal_number) { g_stop_signal.store(signal_number); }

int play(const Schedule& schedule, const ChannelMap& map, const PlayerOptions& opt) {
  std::ostream& out = opt.out ? *opt.out : std::cout;
  std::ostream& err = opt.err ? *opt.err : std::cerr;
  using Mode = PlayerOptions::Mode;

  // ---- 1. Refuse anything beyond a limit before a port is opened. --------------
  schedule.validate();
  map.check_schedule(schedule);
  const auto levels = map.effective_levels(schedule);
  if (!(opt.time_scale > 0) || !(opt.tick_s > 0)) throw InputError("options", "time scale and tick must be positive");

  std::vector<Regulator> regs;
  std::vector<std::unique_ptr<Line>> lines;
  for (int ch = 0; ch < kNumChannels; ++ch) {
    const ChannelSpec* c = map.find(ch);
    if (!c) continue;
    Regulator r;
    r.spec = *c;
    r.dev = *map.device(c->device);
    auto ov = opt.ports.find(r.dev.name);
    if (ov != opt.ports.end())
      r.dev.port = ov->second;
    else if (opt.ports.count(""))
      r.dev.port = opt.ports.at("");
    if (r.dev.port.empty() && !opt.dry_run)
      throw InputError(r.dev.where, "device " + r.dev.name + " has no port (give one in the map or with --port)");
    Line* line = nullptr;
    for (auto& l : lines)
      if (l->path == r.dev.port) line = l.get();
    if (!line) {
      lines.push_back(std::make_unique<Line>());
      line = lines.back().get();
      line->path = r.dev.port;
      line->baud = r.dev.baud;
    }
    r.line = line;
    regs.push_back(r);
  }
  std::vector<int> chans;
  for (auto& r : regs) chans.push_back(r.spec.channel);

  SignalGuard signals(opt.handle_signals);
  CsvLog log(opt.log_path, chans);
  log.meta("morphfem hw log", "v1");
  log.meta("schedule", schedule.source.empty() ? schedule.name : schedule.source);
  log.meta("map", map.source);
  log.meta("column_s", std::to_string(schedule.column_s));
  log.meta("columns", std::to_string(schedule.columns()));
  log.meta("repeats", std::to_string(schedule.repeats));
  log.meta("mode", opt.mode == Mode::fixed ? "fixed" : opt.mode == Mode::settle ? "settle" : "step");
  log.meta("time_scale", std::to_string(opt.time_scale));
  log.meta("dry_run", opt.dry_run ? "yes" : "no");
  log.header();

  const int K = schedule.total_columns();
  int k = -1;      // current column; -1 = settling before column 0
  double tau = 0;  // schedule time spent in the current column
  double t = -schedule.settle_s;
  const double tol_default = 2000;

  std::vector<double> follow(regs.size()), cmd(regs.size(), 0.0), meas(regs.size(), kNaN);
  std::vector<double> off_since(regs.size(), kNaN);
  std::vector<int> off_samples(regs.size(), 0);  // consecutive exchanges out of the band
  auto rates = [&](std::size_t i, double& rise, double& fall) {
    int ch = regs[i].spec.channel;
    const ChannelLevels& l = levels[ch];
    if (ch == kChannelCore) {
      rise = (l.inflate_ramp_s > 0 && l.inflate_pa != 0) ? std::abs(l.inflate_pa) / l.inflate_ramp_s
                                                         : std::numeric_limits<double>::infinity();
      fall = rise;
    } else {
      rise = l.rise_rate();
      fall = l.fall_rate();
    }
  };
  for (std::size_t i = 0; i < regs.size(); ++i)
    follow[i] = regs[i].spec.channel == kChannelCore ? 0.0 : schedule.target_pa(regs[i].spec.channel, -1, levels);

  auto say = [&](const std::string& m) { err << "morphfem hw: " << m << "\n" << std::flush; };

  // ---- 2. Open ports and initialise regulators. -------------------------------
  auto io_timeout = opt.reply_timeout_s;
  std::string fault;
  int code = kExitOk;
  auto init_line = [&](Line& l) {
    for (auto& r : regs)
      if (r.line == &l) r.init(io_timeout);
  };
  auto reconnect = [&](Line& l, const std::string& why) -> bool {
    log.event(t, k, "event", "port " + l.path + " lost (" + why + "); reconnecting");
    if (!l.port->reconnect(opt.reconnect_s)) return false;
    try {
      init_line(l);
    } catch (const DeviceError&) {
      return false;
    }
    log.event(t, k, "event", "port " + l.path + " reconnected");
    return true;
  };

  if (!opt.dry_run) {
    try {
      for (auto& l : lines) {
        l->port = std::make_unique<SerialPort>(l->path, l->baud);
        l->port->open();
        init_line(*l);
      }
      log.event(t, k, "event", "regulators initialised");
    } catch (const DeviceError& e) {
      fault = std::string("could not start: ") + e.what();
      code = kExitFault;
    }
  } else {
    out << "# dry run: command stream of " << (schedule.source.empty() ? schedule.name : schedule.source) << "\n";
    for (auto& r : regs)
      if (r.dev.protocol == Protocol::booth)
        out << "init " << channel_name(r.spec.channel) << " " << r.dev.name << " " << hex_bytes(r.booth_init_request())
            << "\n";
  }

  // ---- 3. Play. ----------------------------------------------------------------
  if (opt.mode == Mode::fixed && schedule.settle_s <= 0) {
    k = 0;  // no settle phase: the first commands are column 1's
    log.event(t, k, "event", "column 1");
  }
  double last_wall = wall_s(), last_display = 0;
  bool finished = false, first_tick = true;
  std::string stop_reason;
  while (code == kExitOk && !finished) {
    if (int sig = g_stop_signal.load()) {
      code = sig == SIGTERM ? kExitSigterm : kExitSigint;
      fault = std::string("stopped by ") + (sig == SIGTERM ? "SIGTERM" : "SIGINT");
      break;
    }
    double dt;
    if (first_tick) {
      dt = 0;  // the first commands go out at the start time
      first_tick = false;
      last_wall = wall_s();
    } else if (opt.dry_run) {
      dt = opt.tick_s * opt.time_scale;
    } else {
      double next = last_wall + opt.tick_s;
      double now = wall_s();
      if (next > now) std::this_thread::sleep_for(std::chrono::duration<double>(next - now));
      now = wall_s();
      dt = (now - last_wall) * opt.time_scale;
      last_wall = now;
    }
    // Advance the column clock and the ramp followers.
    double remaining = dt;
    while (remaining > 0 && !finished) {
      double len;
      if (k < 0)
        len = (opt.mode == Mode::fixed) ? schedule.settle_s : std::numeric_limits<double>::infinity();
      else
        len = (opt.mode == Mode::fixed) ? schedule.column_s : std::numeric_limits<double>::infinity();
      if (k < 0 && opt.mode != Mode::fixed && schedule.settle_s > 0) len = std::numeric_limits<double>::infinity();
      double step = std::min(remaining, std::max(0.0, len - tau));
      for (std::size_t i = 0; i < regs.size(); ++i) {
        double rise, fall;
        rates(i, rise, fall);
        follow[i] = ramp_towards(follow[i], schedule.target_pa(regs[i].spec.channel, k, levels), rise, fall, step);
      }
      tau += step;
      t += step;
      remaining -= step;
      if (tau >= len - 1e-12) {
        ++k;
        tau = 0;
        if (k >= K)
          finished = true;
        else if (opt.mode == Mode::fixed || k == 0)
          log.event(t, k, "event", "column " + std::to_string(k + 1));
      } else {
        break;
      }
    }
    if (finished) break;
    // Commands: slew limit and hard limits.
    for (std::size_t i = 0; i < regs.size(); ++i) {
      const ChannelSpec& s = regs[i].spec;
      double lim = s.ramp_limit_pa_per_s > 0 ? s.ramp_limit_pa_per_s : std::numeric_limits<double>::infinity();
      cmd[i] = std::clamp(ramp_towards(cmd[i], follow[i], lim, lim, dt), s.min_pa, s.max_pa);
    }
    // Exchange with the regulators.
    if (opt.dry_run) {
      for (std::size_t i = 0; i < regs.size(); ++i)
        if (!(std::abs(cmd[i] - regs[i].sent) <= 0.5)) {
          out << "t=" << std::fixed;
          out.precision(3);
          out << (t == 0 ? 0.0 : t) << " " << channel_name(regs[i].spec.channel) << " " << regs[i].dev.name << " tx "
              << regs[i].wire_command(cmd[i]) << "\n";
          out.unsetf(std::ios::fixed);
          regs[i].sent = cmd[i];
        }
    } else {
      try {
        for (std::size_t i = 0; i < regs.size(); ++i) {
          for (int attempt = 0;; ++attempt) {
            try {
              if (!(std::abs(cmd[i] - regs[i].sent) <= 0.5))
                meas[i] = regs[i].command(cmd[i], io_timeout);
              else
                meas[i] = regs[i].poll(io_timeout);
              break;
            } catch (const DisconnectedError& e) {
              if (attempt > 0 || !reconnect(*regs[i].line, e.what()))
                throw DisconnectedError(std::string(e.what()) + "; it did not come back within " +
                                        std::to_string(opt.reconnect_s) + " s");
            }
          }
        }
      } catch (const TimeoutError& e) {
        fault = std::string("reply timeout: ") + e.what();
        code = kExitFault;
      } catch (const DisconnectedError& e) {
        fault = std::string("device disconnected: ") + e.what();
        code = kExitFault;
      } catch (const DeviceError& e) {
        fault = std::string("error reply: ") + e.what();
        code = kExitFault;
      }
    }
    log.sample(t, k, cmd, meas);
    if (code != kExitOk) break;
    // Tracking fault (rupture, leak, stuck valve) and settle detection.
    bool settled = true;
    if (!opt.dry_run) {
      for (std::size_t i = 0; i < regs.size(); ++i) {
        double e = std::abs(meas[i] - cmd[i]);
        if (e > opt.tracking_fault_pa) {
          if (std::isnan(off_since[i])) off_since[i] = t;
          ++off_samples[i];
          if (t - off_since[i] >= opt.tracking_fault_s && off_samples[i] >= opt.tracking_fault_samples) {
            std::ostringstream m;
            m << "tracking fault on " << regs[i].label() << ": measured " << kpa(meas[i]) << " kPa, commanded "
              << kpa(cmd[i]) << " kPa for " << (t - off_since[i]) << " s (ruptured bladder, leak or stuck valve?)";
            fault = m.str();
            code = kExitFault;
            break;
          }
        } else {
          off_since[i] = kNaN;
          off_samples[i] = 0;
        }
        double tol = regs[i].spec.tolerance_pa > 0 ? regs[i].spec.tolerance_pa : tol_default;
        double target =
            std::clamp(schedule.target_pa(regs[i].spec.channel, k, levels), regs[i].spec.min_pa, regs[i].spec.max_pa);
        if (!(e <= tol) || std::abs(cmd[i] - target) > 0.5) settled = false;
      }
    }
    if (code != kExitOk) break;
    if (opt.mode == Mode::settle) {
      bool hold_done = tau >= (k < 0 ? schedule.settle_s : opt.min_hold_s);
      if ((settled || opt.dry_run) && hold_done) {
        log.event(t, k + 1, "event", "settled; column " + std::to_string(k + 2));
        ++k;
        tau = 0;
        if (k >= K) finished = true;
      } else if (k >= 0 && tau > opt.settle_timeout_s) {
        fault = "pressures did not settle within " + std::to_string(opt.settle_timeout_s) + " s in column " +
                std::to_string(k + 1);
        code = kExitFault;
      }
    } else if (opt.mode == Mode::step) {
      pollfd p{opt.step_fd, POLLIN, 0};
      if (::poll(&p, 1, 0) > 0 && (p.revents & (POLLIN | POLLHUP))) {
        char c = 0;
        ssize_t n = ::read(opt.step_fd, &c, 1);
        if (n <= 0 || c == 'q') {
          stop_reason = "stopped by the user";
          finished = true;
        } else if (c == '\n' || c == ' ' || c == 'n') {
          ++k;
          tau = 0;
          log.event(t, k, "event", "step to column " + std::to_string(k + 1));
          if (k >= K) finished = true;
        }
      }
    }
    if (opt.display && wall_s() - last_display > 0.25) {
      last_display = wall_s();
      std::ostringstream d;
      d << "\rt " << std::fixed;
      d.precision(2);
      d << t << " s col " << (k + 1) << "/" << K << " |";
      for (std::size_t i = 0; i < regs.size(); ++i)
        d << " " << channel_name(regs[i].spec.channel) << " " << kpa(cmd[i]) << "/" << kpa(meas[i]);
      d << " kPa\033[K";
      err << d.str() << std::flush;
    }
  }
  if (opt.display) err << "\n";

  // ---- 4. Vent every channel, whatever happened. --------------------------------
  if (code != kExitOk)
    log.event(t, k, "fault", fault);
  else
    log.event(t, k, "event", stop_reason.empty() ? "end of schedule" : stop_reason);
  std::vector<std::string> not_vented;
  if (opt.dry_run) {
    for (auto& r : regs)
      out << "vent " << channel_name(r.spec.channel) << " " << r.dev.name << " tx "
          << (r.dev.protocol == Protocol::alicat ? escape_ascii(alicat_setpoint(char(r.spec.address), 0))
                                                 : hex_bytes(r.booth_setpoint_request(0, booth::kStateVent)))
          << "\n";
  } else {
    const double vent_deadline = wall_s() + opt.vent_reconnect_s;
    for (auto& r : regs) {
      bool ok = false;
      for (int attempt = 0; attempt < 3 && !ok; ++attempt) {
        try {
          if (!r.line->port || !r.line->port->is_open()) {
            if (!r.line->port) r.line->port = std::make_unique<SerialPort>(r.line->path, r.line->baud);
            // Wait for a vanished port, for vent_reconnect_s in total over all channels.
            if (!r.line->port->reconnect(std::max(0.05, vent_deadline - wall_s()))) continue;
          }
          r.vent(io_timeout);
          ok = true;
        } catch (const DisconnectedError&) {
          r.line->port->close();
        } catch (const DeviceError&) {
          // A garbled or missing reply to a vent: try again.
        }
      }
      if (!ok) not_vented.push_back(channel_name(r.spec.channel));
    }
    for (auto& l : lines)
      if (l->port) l->port->close();
  }
  std::string vent_msg;
  if (not_vented.empty()) {
    vent_msg = "all channels vented";
  } else {
    vent_msg = "COULD NOT VENT";
    for (auto& n : not_vented) vent_msg += " " + n;
    vent_msg += ": vent them by hand";
  }
  log.event(t, k, not_vented.empty() ? "event" : "fault", vent_msg);
  log.close();
  if (code != kExitOk) {
    say(fault + "; " + vent_msg);
    if (!not_vented.empty() && code == kExitFault) code = kExitVentFailed;
  } else if (!not_vented.empty()) {
    say(vent_msg);
    code = kExitVentFailed;
  } else if (!opt.dry_run && opt.display) {
    say((stop_reason.empty() ? "schedule complete" : stop_reason) + "; " + vent_msg);
  }
  return code;
}

}  // namespace morphfem::hw
