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
  double sent = kNaN;        // last setpoint acknowledged by the device
  bool pressurised = false;  // a setpoint other than 0 Pa was sent (perhaps unacknowledged)

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
    if (std::abs(pa) > 0.5) pressurised = true;
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

// "column 5" or "columns 5-13" (1-based).
std::string columns_text(int first, int last) {
  if (first == last) return "column " + std::to_string(first + 1);
  return "columns " + std::to_string(first + 1) + "-" + std::to_string(last + 1);
}

std::string seconds_text(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", s);
  return b;
}

// Columns that had no completed exchange for longer than max_gap_s.
struct LostSpan {
  int first_column, last_column;  // -1 = the rest phase
  double from_t, to_t;            // schedule time of the exchanges around the gap (s)
  std::string text() const {
    std::string what = last_column < 0    ? std::string("the rest phase")
                       : first_column < 0 ? "the rest phase and " + columns_text(0, last_column)
                                          : columns_text(first_column, last_column);
    return what + " (" + seconds_text(to_t - from_t) + " s of schedule time without a completed exchange, t " +
           seconds_text(from_t) + "-" + seconds_text(to_t) + " s)";
  }
};

// One run of the player: set-up, the control loop, venting and the report.
class Run {
 public:
  Run(const Schedule& s, const ChannelMap& m, const PlayerOptions& o)
      : s_(s), map_(m), opt_(o), out_(o.out ? *o.out : std::cout), err_(o.err ? *o.err : std::cerr) {}
  int execute();

 private:
  using Mode = PlayerOptions::Mode;
  void check_input();
  void build_regulators();
  void open_log();
  bool start_devices();
  void print_dry_run_init();
  bool stop_requested();
  double next_dt();
  void advance(double dt);
  void enter_column(int k);
  void update_commands(double dt);
  void exchange_dry_run();
  bool exchange();
  void exchange_one(std::size_t i);
  bool reconnect(Line& l, const std::string& why);
  bool account_round();
  void account_end();
  bool watch_pressures();
  bool tracking_fault(std::size_t i, double error);
  void step_modes();
  void show();
  void vent_all();
  bool vent_one(Regulator& r, double deadline);
  int report();
  void fail(int code, const std::string& why) {
    code_ = code;
    fault_ = why;
  }
  void say(const std::string& m) { err_ << "morphfem hw: " << m << "\n" << std::flush; }

  const Schedule& s_;
  const ChannelMap& map_;
  const PlayerOptions& opt_;
  std::ostream& out_;
  std::ostream& err_;
  double tick_s_ = 0.02;
  std::array<ChannelLevels, kNumChannels> levels_{};
  PressurePlan plan_;
  std::vector<Regulator> regs_;
  std::vector<std::unique_ptr<Line>> lines_;
  std::unique_ptr<CsvLog> log_;
  // Clock: column k_ (-1 = settling before column 0), tau_ s into it, schedule time t_.
  int K_ = 0, k_ = -1;
  double tau_ = 0, t_ = 0;
  bool finished_ = false, started_ = false, settled_ = false, round_interrupted_ = false;
  double last_wall_ = 0, last_display_ = 0;
  std::vector<double> follow_, cmd_, meas_, sent_t_, read_t_, off_since_;
  std::vector<int> off_samples_;
  std::vector<PressureWatch> watch_;
  // Columns entered since the last completed exchange: logged once it completes.
  std::vector<std::pair<int, double>> pending_columns_;
  double last_round_t_ = kNaN;
  int last_round_k_ = -1;
  std::vector<LostSpan> lost_;
  int code_ = kExitOk;
  std::string fault_, stop_reason_, vent_msg_;
  std::vector<std::string> not_vented_;
};

void Run::check_input() {
  s_.validate();
  map_.check_schedule(s_);
  if (!(opt_.time_scale > 0)) throw InputError("--time-scale", "must be positive");
  tick_s_ = opt_.tick_s > 0 ? opt_.tick_s : std::max(0.005, 0.02 / opt_.time_scale);
  if (!(opt_.max_gap_s > 0)) throw InputError("--max-gap-s", "must be positive");
  levels_ = map_.effective_levels(s_);
  plan_ = map_.plan(s_);
  const PressurePlan& plan = plan_;
  if (plan.changes.empty()) return;
  const std::string what = "the map changes " + std::to_string(plan.changes.size()) +
                           " pressure(s) (channel and column) of schedule " + (s_.source.empty() ? s_.name : s_.source);
  if (!opt_.allow_map_override)
    throw InputError(map_.source, "refused before sending anything: " + what + ":\n" + plan.describe_changes() +
                                      "give --allow-map-override to play them as listed");
  std::string list = plan.describe_changes();
  list.pop_back();  // say() ends the line
  say(map_.source + ": " + what + " (--allow-map-override):\n" + list);
}

void Run::build_regulators() {
  for (auto& [device, path] : opt_.ports)
    if (!device.empty() && !map_.device(device))
      throw InputError("--port " + device + "=" + path,
                       "the map " + map_.source + " has no device named '" + device + "'");
  for (int ch = 0; ch < kNumChannels; ++ch) {
    const ChannelSpec* c = map_.find(ch);
    if (!c) continue;
    Regulator r;
    r.spec = *c;
    r.dev = *map_.device(c->device);
    auto ov = opt_.ports.find(r.dev.name);
    if (ov != opt_.ports.end())
      r.dev.port = ov->second;
    else if (opt_.ports.count(""))
      r.dev.port = opt_.ports.at("");
    if (r.dev.port.empty() && !opt_.dry_run)
      throw InputError(r.dev.where, "device " + r.dev.name + " has no port (give one in the map or with --port)");
    Line* line = nullptr;
    for (auto& l : lines_)
      if (l->path == r.dev.port) line = l.get();
    if (!line) {
      lines_.push_back(std::make_unique<Line>());
      line = lines_.back().get();
      line->path = r.dev.port;
      line->baud = r.dev.baud;
    }
    r.line = line;
    regs_.push_back(r);
  }
  const std::size_t n = regs_.size();
  follow_.assign(n, 0.0);
  cmd_.assign(n, 0.0);
  meas_.assign(n, kNaN);
  sent_t_.assign(n, kNaN);
  read_t_.assign(n, kNaN);
  off_since_.assign(n, kNaN);
  off_samples_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const int ch = regs_[i].spec.channel;
    follow_[i] = ch == kChannelCore ? 0.0 : s_.target_pa(ch, -1, levels_);
    WatchSettings w = opt_.watch;
    if (regs_[i].spec.min_fill_rate_pa_per_s) w.min_rate_pa_per_s = *regs_[i].spec.min_fill_rate_pa_per_s;
    watch_.emplace_back(w);
  }
}

void Run::open_log() {
  std::vector<int> chans;
  for (auto& r : regs_) chans.push_back(r.spec.channel);
  log_ = std::make_unique<CsvLog>(opt_.log_path, chans);
  CsvLog& log = *log_;
  log.meta("morphfem hw log", "v1");
  log.meta("schedule", s_.source.empty() ? s_.name : s_.source);
  log.meta("map", map_.source);
  log.meta("column_s", std::to_string(s_.column_s));
  log.meta("columns", std::to_string(s_.columns()));
  log.meta("repeats", std::to_string(s_.repeats));
  log.meta("mode", opt_.mode == Mode::fixed ? "fixed" : opt_.mode == Mode::settle ? "settle" : "step");
  log.meta("time_scale", std::to_string(opt_.time_scale));
  log.meta("dry_run", opt_.dry_run ? "yes" : "no");
  std::istringstream changes(plan_.describe_changes());  // played with --allow-map-override
  for (std::string line; std::getline(changes, line);) log.meta("map_change", line.substr(line.find_first_not_of(' ')));
  log.header();
}

// Opens every port and initialises every regulator; no setpoint is sent. On a
// failure the ports are closed and the run ends: nothing was sent.
bool Run::start_devices() {
  try {
    for (auto& l : lines_) {
      l->port = std::make_unique<SerialPort>(l->path, l->baud);
      l->port->open();
      for (auto& r : regs_)
        if (r.line == l.get()) r.init(opt_.reply_timeout_s);
    }
    log_->event(t_, k_, "event", "regulators initialised");
    return true;
  } catch (const DeviceError& e) {
    for (auto& l : lines_)
      if (l->port) l->port->close();
    fail(kExitInput, std::string("could not start: ") + e.what() +
                         "; nothing was sent (no regulator received a setpoint), nothing to vent");
    return false;
  }
}

void Run::print_dry_run_init() {
  out_ << "# dry run: command stream of " << (s_.source.empty() ? s_.name : s_.source) << "\n";
  for (auto& r : regs_)
    if (r.dev.protocol == Protocol::booth)
      out_ << "init " << channel_name(r.spec.channel) << " " << r.dev.name << " " << hex_bytes(r.booth_init_request())
           << "\n";
}

bool Run::stop_requested() {
  const int sig = g_stop_signal.load();
  if (!sig) return false;
  fail(sig == SIGTERM ? kExitSigterm : kExitSigint,
       std::string("stopped by ") + (sig == SIGTERM ? "SIGTERM" : "SIGINT"));
  return true;
}

// Schedule seconds since the previous tick (0 on the first: its commands go out at the start).
double Run::next_dt() {
  if (!started_) {
    started_ = true;
    last_wall_ = wall_s();
    return 0;
  }
  if (opt_.dry_run) return tick_s_ * opt_.time_scale;
  const double next = last_wall_ + tick_s_;
  double now = wall_s();
  if (next > now) std::this_thread::sleep_for(std::chrono::duration<double>(next - now));
  now = wall_s();
  const double dt = (now - last_wall_) * opt_.time_scale;
  last_wall_ = now;
  return dt;
}

void Run::enter_column(int k) {
  k_ = k;
  tau_ = 0;
  if (k_ >= K_)
    finished_ = true;
  else
    pending_columns_.push_back({k_, t_});
}

// Advances the column clock and the ramp followers by dt schedule seconds.
void Run::advance(double dt) {
  const double inf = std::numeric_limits<double>::infinity();
  double remaining = dt;
  while (remaining > 0 && !finished_) {
    double len = inf;  // settle and step modes advance on events
    if (opt_.mode == Mode::fixed) len = k_ < 0 ? s_.settle_s : s_.column_s;
    const double step = std::min(remaining, std::max(0.0, len - tau_));
    for (std::size_t i = 0; i < regs_.size(); ++i) {
      const int ch = regs_[i].spec.channel;
      double rise = levels_[ch].rise_rate(), fall = levels_[ch].fall_rate();
      if (ch == kChannelCore) {
        const ChannelLevels& l = levels_[ch];
        rise = (l.inflate_ramp_s > 0 && l.inflate_pa != 0) ? std::abs(l.inflate_pa) / l.inflate_ramp_s : inf;
        fall = rise;
      }
      follow_[i] = ramp_towards(follow_[i], s_.target_pa(ch, k_, levels_), rise, fall, step);
    }
    tau_ += step;
    t_ += step;
    remaining -= step;
    if (tau_ < len - 1e-12) break;
    enter_column(k_ + 1);
  }
}

// Commands: the followers, slew-limited by the map's ramp limit and clamped to its limits.
void Run::update_commands(double dt) {
  for (std::size_t i = 0; i < regs_.size(); ++i) {
    const ChannelSpec& c = regs_[i].spec;
    const double lim = c.ramp_limit_pa_per_s > 0 ? c.ramp_limit_pa_per_s : std::numeric_limits<double>::infinity();
    cmd_[i] = std::clamp(ramp_towards(cmd_[i], follow_[i], lim, lim, dt), c.min_pa, c.max_pa);
  }
}

void Run::exchange_dry_run() {
  for (std::size_t i = 0; i < regs_.size(); ++i) {
    if (std::abs(cmd_[i] - regs_[i].sent) <= 0.5) continue;
    out_ << "t=" << std::fixed;
    out_.precision(3);
    out_ << (t_ == 0 ? 0.0 : t_) << " " << channel_name(regs_[i].spec.channel) << " " << regs_[i].dev.name << " tx "
         << regs_[i].wire_command(cmd_[i]) << "\n";
    out_.unsetf(std::ios::fixed);
    regs_[i].sent = cmd_[i];
  }
  for (auto& [k, t] : pending_columns_) log_->event(t, k, "event", "column " + std::to_string(k + 1));
  pending_columns_.clear();
}

bool Run::reconnect(Line& l, const std::string& why) {
  log_->event(t_, k_, "event", "port " + l.path + " lost (" + why + "); reconnecting");
  if (!l.port->reconnect(opt_.reconnect_s)) return false;
  try {
    for (auto& r : regs_)
      if (r.line == &l) r.init(opt_.reply_timeout_s);
  } catch (const DeviceError&) {
    return false;
  }
  log_->event(t_, k_, "event", "port " + l.path + " reconnected");
  round_interrupted_ = true;
  return true;
}

// Sends regulator i its command (or polls it) and reads its pressure; one reconnection.
void Run::exchange_one(std::size_t i) {
  Regulator& r = regs_[i];
  for (int attempt = 0;; ++attempt) {
    try {
      sent_t_[i] = t_ + (wall_s() - last_wall_) * opt_.time_scale;
      if (!(std::abs(cmd_[i] - r.sent) <= 0.5))
        meas_[i] = r.command(cmd_[i], opt_.reply_timeout_s);
      else
        meas_[i] = r.poll(opt_.reply_timeout_s);
      // The reading was taken within [sent_t_, read_t_] (schedule time): the host
      // may have stalled since the tick began, or during the exchange.
      read_t_[i] = t_ + (wall_s() - last_wall_) * opt_.time_scale;
      return;
    } catch (const DisconnectedError& e) {
      if (attempt > 0 || !reconnect(*r.line, e.what()))
        throw DisconnectedError(std::string(e.what()) + "; it did not come back within " +
                                std::to_string(opt_.reconnect_s) + " s");
    }
  }
}

bool Run::exchange() {
  try {
    for (std::size_t i = 0; i < regs_.size(); ++i) exchange_one(i);
    return true;
  } catch (const TimeoutError& e) {
    fail(kExitFault, std::string("reply timeout: ") + e.what());
  } catch (const DisconnectedError& e) {
    fail(kExitFault, std::string("device disconnected: ") + e.what());
  } catch (const DeviceError& e) {
    fail(kExitFault, std::string("error reply: ") + e.what());
  }
  return false;
}

// After a completed exchange round: a gap longer than max_gap_s since the previous
// one loses every column it overlaps; otherwise the columns entered since are logged.
bool Run::account_round() {
  const bool gap = std::isfinite(last_round_t_) && t_ - last_round_t_ > opt_.max_gap_s;
  const double from_t = last_round_t_;
  const int from_k = last_round_k_;
  last_round_t_ = t_;
  last_round_k_ = k_;
  if (!gap) {
    for (auto& [k, t] : pending_columns_) log_->event(t, k, "event", "column " + std::to_string(k + 1));
    pending_columns_.clear();
    return true;
  }
  pending_columns_.clear();
  lost_.push_back({from_k, k_, from_t, t_});
  for (auto& w : watch_) w.reset();  // samples before the gap are no evidence
  off_since_.assign(regs_.size(), kNaN);
  off_samples_.assign(regs_.size(), 0);
  const std::string msg = "lost " + lost_.back().text();
  if (!opt_.continue_after_gap) {
    fail(kExitLost, msg);
    return false;
  }
  log_->event(t_, k_, "fault", msg + "; playing on (--continue-after-gap)");
  say(msg + "; playing on (--continue-after-gap)");
  return true;
}

// The schedule ended inside a gap: the columns since the last completed exchange are lost.
void Run::account_end() {
  if (!std::isfinite(last_round_t_) || t_ - last_round_t_ <= opt_.max_gap_s) return;
  lost_.push_back({last_round_k_, K_ - 1, last_round_t_, t_});
  const std::string msg = "lost " + lost_.back().text() + " at the end of the schedule";
  if (!opt_.continue_after_gap) {
    fail(kExitLost, msg);
    return;
  }
  log_->event(t_, k_, "fault", msg);
}

// The slow backstop: |measured - commanded| > tracking_fault_pa for tracking_fault_s
// and tracking_fault_samples consecutive exchanges.
bool Run::tracking_fault(std::size_t i, double error) {
  if (!(error > opt_.tracking_fault_pa)) {
    off_since_[i] = kNaN;
    off_samples_[i] = 0;
    return false;
  }
  if (std::isnan(off_since_[i])) off_since_[i] = t_;
  ++off_samples_[i];
  return t_ - off_since_[i] >= opt_.tracking_fault_s && off_samples_[i] >= opt_.tracking_fault_samples;
}

// Rupture, leak and stuck-valve detection; records whether every channel settled.
bool Run::watch_pressures() {
  settled_ = true;
  for (std::size_t i = 0; i < regs_.size(); ++i) {
    const double e = std::abs(meas_[i] - cmd_[i]);
    std::string why = watch_[i].add(sent_t_[i], read_t_[i], cmd_[i], meas_[i]);
    if (why.empty() && tracking_fault(i, e))
      why = "measured " + kpa(meas_[i]) + " kPa, commanded " + kpa(cmd_[i]) + " kPa for " +
            seconds_text(t_ - off_since_[i]) + " s";
    if (!why.empty()) {
      fail(kExitFault,
           "tracking fault on " + regs_[i].label() + ": " + why + " (ruptured bladder, leak or stuck valve?)");
      return false;
    }
    const ChannelSpec& c = regs_[i].spec;
    const double target = std::clamp(s_.target_pa(c.channel, k_, levels_), c.min_pa, c.max_pa);
    if (!channel_settled(meas_[i], cmd_[i], target, c.tolerance_pa)) settled_ = false;
  }
  return true;
}

// Settle mode: next column once settled and held; step mode: keys.
void Run::step_modes() {
  if (opt_.mode == Mode::settle) {
    const Cadence cadence{Cadence::Mode::settle, opt_.min_hold_s, opt_.settle_timeout_s};
    if (cadence.may_end(k_, tau_, s_.settle_s, settled_ || opt_.dry_run)) {
      log_->event(t_, k_ + 1, "event", "settled; column " + std::to_string(k_ + 2));
      enter_column(k_ + 1);
      pending_columns_.clear();
    } else if (cadence.timed_out(k_, tau_)) {
      fail(kExitFault, "pressures did not settle within " + std::to_string(opt_.settle_timeout_s) + " s in column " +
                           std::to_string(k_ + 1));
    }
    return;
  }
  if (opt_.mode != Mode::step) return;
  pollfd p{opt_.step_fd, POLLIN, 0};
  if (::poll(&p, 1, 0) <= 0 || !(p.revents & (POLLIN | POLLHUP))) return;
  char c = 0;
  const ssize_t n = ::read(opt_.step_fd, &c, 1);
  if (n <= 0 || c == 'q') {
    stop_reason_ = "stopped by the user";
    finished_ = true;
  } else if (c == '\n' || c == ' ' || c == 'n') {
    log_->event(t_, k_ + 1, "event", "step to column " + std::to_string(k_ + 2));
    enter_column(k_ + 1);
    pending_columns_.clear();
  }
}

void Run::show() {
  if (!opt_.display || wall_s() - last_display_ <= 0.25) return;
  last_display_ = wall_s();
  std::ostringstream d;
  d << "\rt " << std::fixed;
  d.precision(2);
  d << t_ << " s col " << (k_ + 1) << "/" << K_ << " |";
  for (std::size_t i = 0; i < regs_.size(); ++i)
    d << " " << channel_name(regs_[i].spec.channel) << " " << kpa(cmd_[i]) << "/" << kpa(meas_[i]);
  d << " kPa\033[K";
  err_ << d.str() << std::flush;
}

// Vents one regulator (3 attempts), reopening a vanished port until `deadline` (wall s).
bool Run::vent_one(Regulator& r, double deadline) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    try {
      if (!r.line->port || !r.line->port->is_open()) {
        if (!r.line->port) r.line->port = std::make_unique<SerialPort>(r.line->path, r.line->baud);
        if (!r.line->port->reconnect(std::max(0.05, deadline - wall_s()))) continue;
      }
      r.vent(opt_.reply_timeout_s);
      return true;
    } catch (const DisconnectedError&) {
      r.line->port->close();
    } catch (const DeviceError&) {
      // A garbled or missing reply to a vent: try again.
    }
  }
  return false;
}

// Vents every channel; only a channel that was sent a pressure and whose vent
// could not be confirmed counts as not vented.
void Run::vent_all() {
  if (opt_.dry_run) {
    for (auto& r : regs_)
      out_ << "vent " << channel_name(r.spec.channel) << " " << r.dev.name << " tx "
           << (r.dev.protocol == Protocol::alicat ? escape_ascii(alicat_setpoint(char(r.spec.address), 0))
                                                  : hex_bytes(r.booth_setpoint_request(0, booth::kStateVent)))
           << "\n";
    vent_msg_ = "all channels vented";
    return;
  }
  const double deadline = wall_s() + opt_.vent_reconnect_s;
  std::vector<std::string> unreached;
  for (auto& r : regs_)
    if (!vent_one(r, deadline)) (r.pressurised ? not_vented_ : unreached).push_back(channel_name(r.spec.channel));
  for (auto& l : lines_)
    if (l->port) l->port->close();
  vent_msg_ = not_vented_.empty() ? "all channels vented" : "COULD NOT VENT";
  for (auto& n : not_vented_) vent_msg_ += " " + n;
  if (!not_vented_.empty()) vent_msg_ += ": vent them by hand";
  if (!unreached.empty()) {
    vent_msg_ += "; not reached (never sent a pressure):";
    for (auto& n : unreached) vent_msg_ += " " + n;
  }
}

int Run::report() {
  std::string summary;
  for (auto& l : lost_) summary += (summary.empty() ? "lost " : "; lost ") + l.text();
  if (code_ != kExitOk) {
    say(fault_ + "; " + vent_msg_);
    const bool fault = code_ == kExitFault || code_ == kExitLost;
    return fault && !not_vented_.empty() ? kExitVentFailed : code_;
  }
  if (!summary.empty()) say("schedule played to the end with " + summary + "; " + vent_msg_);
  if (!not_vented_.empty()) {
    say(vent_msg_);
    return kExitVentFailed;
  }
  if (!opt_.dry_run && opt_.display && summary.empty())
    say((stop_reason_.empty() ? "schedule complete" : stop_reason_) + "; " + vent_msg_);
  return kExitOk;
}

int Run::execute() {
  check_input();
  build_regulators();
  SignalGuard signals(opt_.handle_signals);
  open_log();
  K_ = s_.total_columns();
  t_ = -s_.settle_s;
  if (opt_.dry_run)
    print_dry_run_init();
  else if (!start_devices()) {
    log_->event(t_, k_, "fault", fault_);
    log_->close();
    say(fault_);
    return code_;
  }
  if (opt_.mode == Mode::fixed && s_.settle_s <= 0) enter_column(0);  // no settle phase: column 1 first
  while (!finished_ && !stop_requested()) {
    const double dt = next_dt();
    advance(dt);
    if (finished_) break;
    update_commands(dt);
    if (opt_.dry_run) {
      exchange_dry_run();
    } else {
      const bool ok = exchange();
      log_->sample(t_, k_, cmd_, meas_);
      if (!ok) break;
      // A round interrupted by a reconnection read some pressures late: it neither
      // closes a gap nor feeds the detectors; the next round does.
      const bool interrupted = round_interrupted_;
      round_interrupted_ = false;
      if (!interrupted && (!account_round() || !watch_pressures())) break;
    }
    step_modes();
    if (code_ != kExitOk) break;
    show();
  }
  if (opt_.display) err_ << "\n";
  if (finished_ && code_ == kExitOk && !opt_.dry_run) account_end();
  if (code_ != kExitOk)
    log_->event(t_, k_, "fault", fault_);
  else
    log_->event(t_, k_, "event", stop_reason_.empty() ? "end of schedule" : stop_reason_);
  vent_all();
  log_->event(t_, k_, not_vented_.empty() ? "event" : "fault", vent_msg_);
  log_->close();
  return report();
}

}  // namespace

void take_cadence(const Cadence& cadence, PlayerOptions& options) {
  options.mode = cadence.mode == Cadence::Mode::settle ? PlayerOptions::Mode::settle : PlayerOptions::Mode::fixed;
  options.min_hold_s = cadence.min_hold_s;
  options.settle_timeout_s = cadence.timeout_s;
}

int play(const Schedule& schedule, const ChannelMap& map, const PlayerOptions& options) {
  return Run(schedule, map, options).execute();
}

}  // namespace morphfem::hw
