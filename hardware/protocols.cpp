#include "hardware/protocols.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace morphfem::hw {

std::string alicat_poll(char id) { return std::string(1, id) + "\r"; }

std::string alicat_setpoint(char id, double pa) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%cS %.3f\r", id, pa / 1000.0);
  return buf;
}

std::string format_alicat_frame(const AlicatFrame& f) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%c %+08.3f %+08.3f", f.id, f.pressure_pa / 1000.0, f.setpoint_pa / 1000.0);
  std::string s = buf;
  for (auto& t : f.status) s += " " + t;
  return s + "\r";
}

namespace {
// Strict signed decimal: [+-]digits[.digits]
bool parse_decimal(std::string_view tok, double& out) {
  if (tok.empty() || tok.size() > 20) return false;
  std::size_t i = 0;
  if (tok[0] == '+' || tok[0] == '-') i = 1;
  bool digits = false, dot = false;
  for (std::size_t j = i; j < tok.size(); ++j) {
    char c = tok[j];
    if (c >= '0' && c <= '9')
      digits = true;
    else if (c == '.' && !dot)
      dot = true;
    else
      return false;
  }
  if (!digits) return false;
  std::string s(tok);
  out = std::strtod(s.c_str(), nullptr);
  return std::isfinite(out);
}
}  // namespace

AlicatReply parse_alicat_reply(std::string_view line, char expect_id) {
  AlicatReply r;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (line == "?" || (line.size() == 3 && line[0] == expect_id && line.substr(1) == " ?")) {
    r.status = ReplyStatus::rejected;
    return r;
  }
  std::vector<std::string_view> tok;
  std::size_t i = 0;
  while (i < line.size()) {
    char c = line[i];
    if (c == ' ') {
      ++i;
      continue;
    }
    if (static_cast<unsigned char>(c) < 0x21 || static_cast<unsigned char>(c) > 0x7e) {
      r.error = "non-printable byte in reply";
      return r;
    }
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ') ++j;
    tok.push_back(line.substr(i, j - i));
    i = j;
  }
  if (tok.size() < 3) {
    r.error = "data frame too short (" + std::to_string(tok.size()) + " fields)";
    return r;
  }
  if (tok[0].size() != 1 || tok[0][0] != expect_id) {
    r.error = "reply from unit '" + std::string(tok[0]) + "', expected '" + std::string(1, expect_id) + "'";
    return r;
  }
  double p, sp;
  if (!parse_decimal(tok[1], p) || !parse_decimal(tok[2], sp)) {
    r.error = "bad number in data frame";
    return r;
  }
  for (std::size_t k = 3; k < tok.size(); ++k) {
    auto t = tok[k];
    bool ok = t.size() == 3;
    for (char c : t) ok = ok && c >= 'A' && c <= 'Z';
    if (!ok) {
      r.error = "bad status token '" + std::string(t) + "'";
      return r;
    }
    r.frame.status.emplace_back(t);
  }
  r.frame.id = expect_id;
  r.frame.pressure_pa = p * 1000.0;
  r.frame.setpoint_pa = sp * 1000.0;
  r.status = ReplyStatus::ok;
  return r;
}

namespace booth {

std::uint8_t crc8(const std::uint8_t* data, std::size_t n) {
  std::uint8_t crc = 0;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= data[i];
    for (int b = 0; b < 8; ++b)
      crc = (crc & 0x80) ? static_cast<std::uint8_t>((crc << 1) ^ 0x07) : static_cast<std::uint8_t>(crc << 1);
  }
  return crc;
}

int Sensor::counts(double pa) const {
  double x = 1023.0 * (0.1 + 0.8 * (pa - min_pa) / (max_pa - min_pa));
  if (!(x > 0)) return 0;
  if (x > 1023) return 1023;
  return static_cast<int>(std::lround(x));
}

double Sensor::pressure(int counts) const { return min_pa + (counts / 1023.0 - 0.1) / 0.8 * (max_pa - min_pa); }

void put_counts(int counts, std::uint8_t& hi, std::uint8_t& lo) {
  unsigned v = static_cast<unsigned>(counts & 0x3ff) << 6;
  hi = static_cast<std::uint8_t>(v >> 8);
  lo = static_cast<std::uint8_t>(v & 0xff);
}

int get_counts(std::uint8_t hi, std::uint8_t lo) { return ((hi << 8) | lo) >> 6; }

namespace {
std::vector<std::uint8_t> finish(std::vector<std::uint8_t> f) {
  f.push_back(crc8(f.data() + 1, f.size() - 1));
  return f;
}
}  // namespace

std::vector<std::uint8_t> write_request(int addr, int reg, const std::vector<std::uint8_t>& data) {
  std::vector<std::uint8_t> f = {kRequestSync, kCmdWrite, static_cast<std::uint8_t>(addr),
                                 static_cast<std::uint8_t>(reg), static_cast<std::uint8_t>(data.size())};
  f.insert(f.end(), data.begin(), data.end());
  return finish(std::move(f));
}

std::vector<std::uint8_t> read_request(int addr, int reg, int len) {
  return finish({kRequestSync, kCmdRead, static_cast<std::uint8_t>(addr), static_cast<std::uint8_t>(reg),
                 static_cast<std::uint8_t>(len)});
}

std::vector<std::uint8_t> reply_frame(std::uint8_t status, int addr, const std::vector<std::uint8_t>& data) {
  std::vector<std::uint8_t> f = {kReplySync, status, static_cast<std::uint8_t>(addr),
                                 static_cast<std::uint8_t>(data.size())};
  f.insert(f.end(), data.begin(), data.end());
  return finish(std::move(f));
}

Parse parse_reply(const std::uint8_t* buf, std::size_t n, Frame& out, std::size_t& consumed, std::string& error) {
  consumed = 0;
  if (n == 0) return Parse::need_more;
  if (buf[0] != kReplySync) {
    consumed = 1;
    error = "reply does not start with the sync byte 5A";
    return Parse::bad;
  }
  if (n < 4) return Parse::need_more;
  std::size_t len = buf[3];
  if (len > kRegisters) {
    consumed = 1;
    error = "reply length " + std::to_string(len) + " exceeds 32";
    return Parse::bad;
  }
  if (buf[1] > kStatusBadCommand) {
    consumed = 1;
    error = "unknown reply status " + std::to_string(buf[1]);
    return Parse::bad;
  }
  std::size_t total = 4 + len + 1;
  if (n < total) return Parse::need_more;
  if (crc8(buf + 1, total - 2) != buf[total - 1]) {
    consumed = 1;
    error = "reply CRC mismatch";
    return Parse::bad;
  }
  out.cmd_or_status = buf[1];
  out.addr = buf[2];
  out.reg = 0;
  out.data.assign(buf + 4, buf + 4 + len);
  consumed = total;
  return Parse::ok;
}

Parse parse_request(const std::uint8_t* buf, std::size_t n, Frame& out, std::size_t& consumed, std::string& error) {
  consumed = 0;
  if (n == 0) return Parse::need_more;
  if (buf[0] != kRequestSync) {
    consumed = 1;
    error = "request does not start with A5";
    return Parse::bad;
  }
  if (n < 5) return Parse::need_more;
  std::uint8_t cmd = buf[1];
  std::size_t len = buf[4];
  if (len > kRegisters) {
    consumed = 1;
    error = "request length exceeds 32";
    return Parse::bad;
  }
  std::size_t total = 5 + (cmd == kCmdWrite ? len : 0) + 1;
  if (n < total) return Parse::need_more;
  if (crc8(buf + 1, total - 2) != buf[total - 1]) {
    consumed = total;
    error = "request CRC mismatch";
    return Parse::bad;
  }
  out.cmd_or_status = cmd;
  out.addr = buf[2];
  out.reg = buf[3];
  out.data.assign(buf + 5, buf + total - 1);
  if (cmd != kCmdWrite) out.data.assign(1, static_cast<std::uint8_t>(len));  // read: data[0] = len
  consumed = total;
  return Parse::ok;
}

}  // namespace booth

std::string hex_bytes(const std::vector<std::uint8_t>& bytes) {
  std::string s;
  char buf[4];
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02X", bytes[i]);
    if (i) s += ' ';
    s += buf;
  }
  return s;
}

std::string escape_ascii(std::string_view in) {
  std::string s;
  char buf[8];
  for (unsigned char c : in) {
    if (c == '\r')
      s += "\\r";
    else if (c == '\n')
      s += "\\n";
    else if (c < 0x20 || c > 0x7e) {
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      s += buf;
    } else
      s += static_cast<char>(c);
  }
  return s;
}

}  // namespace morphfem::hw
