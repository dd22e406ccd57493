#include "pbvbus/gateways/slcan.hpp"

#include <cstdio>

namespace pbvbus::gateways::slcan {

namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

/// Parses exactly s.size() hex digits (at most 8).
std::optional<std::uint32_t> hex(std::string_view s) {
  if (s.empty() || s.size() > 8) return std::nullopt;
  std::uint32_t v = 0;
  for (char c : s) {
    const int d = hex_digit(c);
    if (d < 0) return std::nullopt;
    v = (v << 4) | static_cast<std::uint32_t>(d);
  }
  return v;
}

Parsed fail(std::string msg) { return Parsed{std::nullopt, std::move(msg)}; }
Parsed ok(Op op, std::uint32_t value = 0) { return Parsed{Command{op, value, {}}, {}}; }

/// A one-character command with one decimal digit argument in [0, max].
Parsed digit_arg(std::string_view line, Op op, int max) {
  if (line.size() != 2 || line[1] < '0' || line[1] > '0' + max)
    return fail(std::string("'") + line[0] + "' needs one digit 0.." + std::to_string(max));
  return ok(op, static_cast<std::uint32_t>(line[1] - '0'));
}

Parsed frame_cmd(std::string_view line) {
  const char c = line[0];
  const bool ext = c == 'T' || c == 'R';
  const bool rtr = c == 'r' || c == 'R';
  const std::size_t id_len = ext ? 8 : 3;
  if (line.size() < 1 + id_len + 1) return fail("frame command too short");
  const auto id = hex(line.substr(1, id_len));
  if (!id) return fail("frame identifier is not hex");
  if (*id > (ext ? 0x1FFFFFFFu : 0x7FFu)) return fail("frame identifier out of range");
  const char l = line[1 + id_len];
  if (l < '0' || l > '8') return fail("DLC must be 0..8");
  const auto dlc = static_cast<std::uint8_t>(l - '0');
  const std::size_t data_len = rtr ? 0 : 2u * dlc;
  if (line.size() != 2 + id_len + data_len) return fail("frame length does not match its DLC");
  CanFrame f;
  f.id = *id;
  f.extended = ext;
  f.rtr = rtr;
  f.dlc = dlc;
  for (std::size_t i = 0; i < data_len / 2; ++i) {
    const auto b = hex(line.substr(2 + id_len + 2 * i, 2));
    if (!b) return fail("frame data is not hex");
    f.data[i] = static_cast<std::uint8_t>(*b);
  }
  return Parsed{Command{Op::Send, 0, f}, {}};
}

}  // namespace

Parsed parse_line(std::string_view line) {
  if (line.empty()) return ok(Op::Empty);
  if (line.size() > kMaxLine) return fail("line too long");
  const char c = line[0];
  const auto bare = [&](Op op) { return line.size() == 1 ? ok(op) : fail(std::string("'") + c + "' takes no argument"); };
  switch (c) {
    case 'S': return digit_arg(line, Op::SetBitrate, 8);
    case 's': {
      if (line.size() != 5) return fail("'s' needs 4 hex digits (BTR0 BTR1)");
      const auto v = hex(line.substr(1));
      return v ? ok(Op::SetBtr, *v) : fail("'s' needs 4 hex digits (BTR0 BTR1)");
    }
    case 'O': return bare(Op::Open);
    case 'L': return bare(Op::ListenOnly);
    case 'C': return bare(Op::Close);
    case 't':
    case 'T':
    case 'r':
    case 'R': return frame_cmd(line);
    case 'F': return bare(Op::ReadFlags);
    case 'V': return bare(Op::Version);
    case 'v': return bare(Op::SoftwareVersion);
    case 'N': return bare(Op::SerialNumber);
    case 'Z': return digit_arg(line, Op::Timestamps, 1);
    case 'M':
    case 'm': {
      const Op op = c == 'M' ? Op::AcceptanceCode : Op::AcceptanceMask;
      if (line.size() != 9) return fail(std::string("'") + c + "' needs 8 hex digits");
      const auto v = hex(line.substr(1));
      return v ? ok(op, *v) : fail(std::string("'") + c + "' needs 8 hex digits");
    }
    case 'X': return digit_arg(line, Op::AutoPoll, 1);
    case 'Q': return digit_arg(line, Op::AutoStart, 2);
    case 'U': return digit_arg(line, Op::UartRate, 6);
    case 'P': return bare(Op::PollOne);
    case 'A': return bare(Op::PollAll);
    default: return fail("unknown command");
  }
}

std::string encode_frame(const CanFrame& f, std::optional<std::uint16_t> timestamp_ms) {
  char buf[48];
  const unsigned dlc = f.dlc > 8 ? 8u : f.dlc;
  const char kind = f.extended ? (f.rtr ? 'R' : 'T') : (f.rtr ? 'r' : 't');
  int n = f.extended ? std::snprintf(buf, sizeof buf, "%c%08X%u", kind, static_cast<unsigned>(f.id & 0x1FFFFFFFu), dlc)
                     : std::snprintf(buf, sizeof buf, "%c%03X%u", kind, static_cast<unsigned>(f.id & 0x7FFu), dlc);
  std::string s(buf, static_cast<std::size_t>(n));
  if (!f.rtr) {
    for (unsigned i = 0; i < dlc; ++i) {
      std::snprintf(buf, sizeof buf, "%02X", f.data[i]);
      s += buf;
    }
  }
  if (timestamp_ms) {
    std::snprintf(buf, sizeof buf, "%04X", static_cast<unsigned>(*timestamp_ms));
    s += buf;
  }
  s += '\r';
  return s;
}

std::uint16_t timestamp_ms(bus::Ticks t) {
  if (t < 0) t = 0;
  return static_cast<std::uint16_t>((t / bus::kTicksPerMs) % 60000);
}

std::string serial_reply(std::string_view serial) {
  std::string s = "N";
  s += serial.substr(0, 4);
  while (s.size() < 5) s += '0';
  s += '\r';
  return s;
}

std::string flags_reply(std::uint8_t flags) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "F%02X\r", static_cast<unsigned>(flags));
  return buf;
}

void SlcanSession::feed(std::string_view bytes, std::string& reply, std::vector<CanFrame>& to_bus) {
  for (char c : bytes) {
    if (c == '\n') continue;
    if (c == '\r') {
      if (m_discarding) {
        m_discarding = false;
        ++m_stats.lines;
        ++m_stats.errors;
        ++m_stats.overlong;
        reply += kError;
      } else {
        handle_line(m_line, reply, to_bus);
      }
      m_line.clear();
      continue;
    }
    if (m_discarding) continue;
    if (m_line.size() >= kMaxLine) {
      m_discarding = true;  // answered once, at its '\r'
      m_line.clear();
      continue;
    }
    m_line += c;
  }
}

void SlcanSession::handle_line(std::string_view line, std::string& reply,
                               std::vector<CanFrame>& to_bus) {
  ++m_stats.lines;
  const Parsed p = parse_line(line);
  const auto refuse = [&] {
    ++m_stats.errors;
    reply += kError;
  };
  if (!p.command) return refuse();
  const Command& c = *p.command;
  switch (c.op) {
    case Op::SetBitrate:
    case Op::SetBtr:
      if (m_open) return refuse();
      reply += kOk;
      return;
    case Op::Open:
    case Op::ListenOnly:
      m_open = true;
      m_listen_only = c.op == Op::ListenOnly;
      reply += kOk;
      return;
    case Op::Close:
      m_open = false;
      m_listen_only = false;
      reply += kOk;
      return;
    case Op::Send:
      if (!m_open || m_listen_only) return refuse();
      ++m_stats.frames_in;
      to_bus.push_back(c.frame);
      reply += c.frame.extended ? kSentExtended : kSentStandard;
      return;
    case Op::ReadFlags:
      reply += flags_reply(m_flags);
      m_flags = 0;
      return;
    case Op::Version: reply += kVersion; return;
    case Op::SoftwareVersion: reply += kSoftwareVersion; return;
    case Op::SerialNumber: reply += serial_reply(m_serial); return;
    case Op::Timestamps:
      m_timestamps = c.value == 1;
      reply += kOk;
      return;
    case Op::Empty:
    case Op::AcceptanceCode:
    case Op::AcceptanceMask:
    case Op::AutoPoll:
    case Op::AutoStart:
    case Op::UartRate:
    case Op::PollOne:
    case Op::PollAll: reply += kOk; return;
  }
  refuse();
}

std::optional<std::string> SlcanSession::frame_to_host(const CanFrame& f, bus::Ticks now) const {
  if (!m_open) return std::nullopt;
  return encode_frame(f, m_timestamps ? std::optional<std::uint16_t>(timestamp_ms(now))
                                      : std::nullopt);
}

}  // namespace pbvbus::gateways::slcan
