#include "pbvbus/captures/pcapng_writer.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <iterator>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/fdl/decoded_frame.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::captures {

namespace {

constexpr std::size_t kBufferSize = 1u << 20;
/// Hold-back buffer: reserved up front; compacted when it grows past this while records stay
/// held (they are released as soon as the overlap ends, so this is a safety net).
constexpr std::size_t kHoldReserve = 1u << 16;

inline void put16(std::uint8_t* p, std::uint16_t v) {
  std::memcpy(p, &v, 2);
}
inline void put32(std::uint8_t* p, std::uint32_t v) {
  std::memcpy(p, &v, 4);
}
inline void put64(std::uint8_t* p, std::uint64_t v) {
  std::memcpy(p, &v, 8);
}
static_assert(std::endian::native == std::endian::little,
              "the writer emits native-order (little-endian) sections");

/// max(bus::ticks_to_ns(t), 0): floor(t * 1000 / 3636) = floor(t * 250 / 909), in one
/// multiplication and one division by a constant while t * 250 fits (t below 2^55 ticks, about
/// 115 days), else as bus::ticks_to_ns() does it.
inline std::uint64_t timestamp_ns(bus::Ticks t) {
  if (t <= 0) return 0;
  const auto u = static_cast<std::uint64_t>(t);
  if (u < (std::uint64_t{1} << 55)) return u * 250 / 909;
  return static_cast<std::uint64_t>(bus::ticks_to_ns(t));
}

using pcapng::pad4;
constexpr std::size_t option_size(std::size_t value_len) {
  return 4 + pad4(value_len);
}

/// Writes an option at p; returns the octets used (padding zeroed).
std::size_t put_option(std::uint8_t* p, std::uint16_t code, const void* value, std::size_t len) {
  put16(p, code);
  put16(p + 2, static_cast<std::uint16_t>(len));
  if (len > 0) std::memcpy(p + 4, value, len);
  const std::size_t total = option_size(len);
  std::memset(p + 4 + len, 0, total - 4 - len);
  return total;
}

std::string baud_description(std::uint64_t speed, std::string_view profile = "PROFIBUS-DP") {
  // "PROFIBUS-DP 1.5 Mbit/s", "PROFIBUS-DP 187.5 kbit/s"; integer arithmetic only.
  auto frac = [](std::uint64_t v, std::uint64_t unit) {
    std::string s = std::to_string(v / unit);
    std::uint64_t rest = v % unit;
    if (rest != 0) {
      std::string digits;
      for (std::uint64_t u = unit / 10; u > 0 && rest != 0; u /= 10) {
        digits += static_cast<char>('0' + rest / u);
        rest %= u;
      }
      s += "." + digits;
    }
    return s;
  };
  const std::string p(profile);
  if (speed >= 1'000'000) return p + " " + frac(speed, 1'000'000) + " Mbit/s";
  if (speed >= 1'000) return p + " " + frac(speed, 1'000) + " kbit/s";
  return p + " " + std::to_string(speed) + " bit/s";
}

void append_reason(std::string& s, std::string_view r) {
  if (!s.empty()) s += ", ";
  s += r;
}

std::string station_name(const bus::Line& line, int a) {
  if (a < 0 || a >= line.attachment_count()) return "station #" + std::to_string(a);
  const std::string& l = line.label(a);
  if (!l.empty()) return l;
  return std::string(const_cast<bus::Line&>(line).device(a).kind()) + " #" + std::to_string(a);
}

}  // namespace

std::uint32_t classify_frame(std::span<const std::uint8_t> bytes, std::uint16_t rx_flags,
                             std::uint32_t sent_len, std::string& comment) {
  comment.clear();
  std::uint32_t flags = 0;
  if (rx_flags & bus::kRxCollision) {
    flags |= pcapng::kFlagSymbolError;
    append_reason(comment, "collision");
  }
  if (rx_flags & bus::kRxParity) {
    flags |= pcapng::kFlagCrcError;
    append_reason(comment, "parity error");
  }
  if (rx_flags & bus::kRxFraming) {
    flags |= pcapng::kFlagCrcError;
    append_reason(comment, "framing error");
  }
  if (rx_flags & bus::kRxPartial) {
    flags |= pcapng::kFlagTooShort;
    char buf[64];
    std::snprintf(buf, sizeof buf, "partial: %zu of %u octets", bytes.size(),
                  static_cast<unsigned>(std::max<std::size_t>(sent_len, bytes.size())));
    append_reason(comment, buf);
  }
  if (rx_flags & bus::kRxBabble) {
    flags |= pcapng::kFlagWrongIfg;
    append_reason(comment, "babbling transmitter");
  }
  fdl::Telegram t;
  const fdl::DecodeError err = fdl::decode(bytes, t);
  switch (err) {
    case fdl::DecodeError::None:
      break;
    case fdl::DecodeError::BadFcs:
      flags |= pcapng::kFlagCrcError;
      break;
    case fdl::DecodeError::Empty:
    case fdl::DecodeError::Truncated:
      flags |= pcapng::kFlagTooShort;
      break;
    case fdl::DecodeError::TrailingOctets:
      flags |= pcapng::kFlagTooLong;
      break;
    case fdl::DecodeError::UnknownDelimiter:
    case fdl::DecodeError::BadSecondDelimiter:
    case fdl::DecodeError::BadEndDelimiter:
      flags |= pcapng::kFlagStartDelimiterError;
      break;
    default:
      break;  // well formed on the wire, invalid for FDL: comment only
  }
  // A partial frame is truncated by definition; saying so twice helps nobody.
  if (err != fdl::DecodeError::None &&
      !(err == fdl::DecodeError::Truncated && (rx_flags & bus::kRxPartial)))
    append_reason(comment, fdl::to_string(err));
  return flags;
}

std::string describe_line_event(const bus::LineEvent& e) {
  std::string s;
  if (e.line) s = e.line->name() + ": ";
  auto name = [&](int a) {
    return e.line ? station_name(*e.line, a) : "station #" + std::to_string(a);
  };
  switch (e.kind) {
    case bus::LineEventKind::CableCut:
    case bus::LineEventKind::CableRepaired:
      s += e.kind == bus::LineEventKind::CableCut ? "cable cut" : "cable repaired";
      if (e.b >= 0)
        s += " between '" + name(e.a) + "' and '" + name(e.b) + "'";
      else
        s += " after '" + name(e.a) + "' (end of the line)";
      break;
    case bus::LineEventKind::NoiseOn:
      s += "noise on: " + std::to_string(e.value) + " bit errors per 10^9 bits";
      break;
    case bus::LineEventKind::ShortCircuit:
    case bus::LineEventKind::ShortRepaired:
    case bus::LineEventKind::NoiseOff:
      s += bus::to_string(e.kind);
      break;
    default:
      s += bus::to_string(e.kind);
      if (e.a >= 0) s += ": '" + name(e.a) + "'";
      break;
  }
  return s;
}

PcapngWriter::PcapngWriter(Sink sink, PcapngWriterOptions opts)
    : m_sink(std::move(sink)), m_opts(std::move(opts)) {
  m_buf.resize(kBufferSize);
  m_event_buf.resize(kEventHeaderSize + kEventMaxText);
  m_comment.reserve(256);
  m_s7_buf.reserve(512);
  m_lines.reserve(16);
  m_known_lines.reserve(16);
  m_held.reserve(256);
  m_hold.reserve(kHoldReserve);
  m_hold_spare.reserve(kHoldReserve);
  write_shb();
}

PcapngWriter::~PcapngWriter() {
  flush();
}

std::unique_ptr<PcapngWriter> PcapngWriter::open(const std::string& path, PcapngWriterOptions opts,
                                                 std::string* error) {
  if (path == "-") {
    opts.streaming = true;
    return std::make_unique<PcapngWriter>(
        [](std::span<const std::uint8_t> b) {
          return std::fwrite(b.data(), 1, b.size(), stdout) == b.size() && std::fflush(stdout) == 0;
        },
        std::move(opts));
  }
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    if (error) *error = "cannot open '" + path + "' for writing: " + std::strerror(errno);
    return nullptr;
  }
  std::shared_ptr<std::FILE> file(f, [](std::FILE* p) { std::fclose(p); });
  const bool streaming = opts.streaming;
  return std::make_unique<PcapngWriter>(
      [file, streaming](std::span<const std::uint8_t> b) {
        if (std::fwrite(b.data(), 1, b.size(), file.get()) != b.size()) return false;
        return !streaming || std::fflush(file.get()) == 0;
      },
      std::move(opts));
}

std::uint8_t* PcapngWriter::reserve(std::size_t n) {
  if (m_len + n > m_buf.size()) {
    flush_buffer();
    if (n > m_buf.size()) m_buf.resize(n);
  }
  std::uint8_t* p = m_buf.data() + m_len;
  m_len += n;
  return p;
}

bool PcapngWriter::flush() {
  release(bus::kNever);
  return flush_buffer();
}

bool PcapngWriter::flush_buffer() {
  if (m_len == 0) return m_ok;
  if (m_ok && !m_sink(std::span<const std::uint8_t>(m_buf.data(), m_len))) {
    m_ok = false;
    m_error = "write failed";
  }
  m_len = 0;
  return m_ok;
}

void PcapngWriter::block_done() {
  if (m_opts.streaming) flush_buffer();
}

void PcapngWriter::write_shb() {
  const std::string& app = m_opts.application;
  const std::size_t opts = (app.empty() ? 0 : option_size(app.size()) + 4);
  const std::size_t total = 28 + opts;
  std::uint8_t* p = reserve(total);
  put32(p, pcapng::kBlockShb);
  put32(p + 4, static_cast<std::uint32_t>(total));
  put32(p + 8, pcapng::kByteOrderMagic);
  put16(p + 12, 1);
  put16(p + 14, 0);
  put64(p + 16, ~std::uint64_t{0});  // section length not specified
  std::size_t o = 24;
  if (!app.empty()) {
    o += put_option(p + o, pcapng::kShbUserAppl, app.data(), app.size());
    o += put_option(p + o, pcapng::kOptEndOfOpt, nullptr, 0);
  }
  put32(p + o, static_cast<std::uint32_t>(total));
  block_done();
}

std::uint32_t PcapngWriter::add_interface(std::string_view name, std::string_view description,
                                          pcapng::LinkType type, std::uint64_t speed) {
  const std::size_t opts = option_size(name.size()) + option_size(description.size()) +
                           (speed ? option_size(8) : 0) + option_size(1) + 4;
  const std::size_t total = 20 + opts;
  std::uint8_t* p = reserve(total);
  put32(p, pcapng::kBlockIdb);
  put32(p + 4, static_cast<std::uint32_t>(total));
  put16(p + 8, static_cast<std::uint16_t>(type));
  put16(p + 10, 0);
  put32(p + 12, 0);  // snaplen: no limit
  std::size_t o = 16;
  o += put_option(p + o, pcapng::kIfName, name.data(), name.size());
  o += put_option(p + o, pcapng::kIfDescription, description.data(), description.size());
  if (speed) {
    std::uint8_t v[8];
    put64(v, speed);
    o += put_option(p + o, pcapng::kIfSpeed, v, 8);
  }
  const std::uint8_t tsresol = 9;
  o += put_option(p + o, pcapng::kIfTsresol, &tsresol, 1);
  o += put_option(p + o, pcapng::kOptEndOfOpt, nullptr, 0);
  put32(p + o, static_cast<std::uint32_t>(total));
  block_done();
  return m_next_if++;
}

std::uint32_t PcapngWriter::add_line(const bus::Line& line) {
  return declare(line, -1, {}, {});
}

std::uint32_t PcapngWriter::add_probe(const bus::Line& line, bus::AttachmentId at,
                                      std::string_view name, std::string_view where) {
  return declare(line, at, name, where);
}

std::uint32_t PcapngWriter::declare(const bus::Line& line, int probe, std::string_view name,
                                    std::string_view where) {
  for (const LineIf& l : m_lines)
    if (l.line == &line && l.probe == probe) return l.id;
  const auto speed = static_cast<std::uint64_t>(line.baud());
  const bool mpi =
      std::find(m_mpi_lines.begin(), m_mpi_lines.end(), &line) != m_mpi_lines.end();
  std::string desc = baud_description(speed, mpi ? "MPI" : "PROFIBUS-DP");
  if (probe >= 0) desc += ", probe at " + (where.empty() ? station_name(line, probe) : std::string(where));
  const std::uint32_t id = add_interface(name.empty() ? std::string_view(line.name()) : name, desc,
                                         m_opts.line_link_type, speed);
  m_lines.push_back({&line, probe, id});
  if (std::find(m_known_lines.begin(), m_known_lines.end(), &line) == m_known_lines.end())
    m_known_lines.push_back(&line);
  return id;
}

void PcapngWriter::declare_taps_of(const bus::Line& line) {
  std::vector<int> points;
  if (line.is_whole_line_tap(*this)) points.push_back(-1);
  for (bus::AttachmentId a : line.probe_points(*this)) points.push_back(a);
  std::size_t existing = 0;
  for (const LineIf& l : m_lines) existing += l.line == &line;
  const bool several = existing + points.size() > 1;
  for (int p : points) {
    bool known = false;
    for (const LineIf& l : m_lines) known |= l.line == &line && l.probe == p;
    if (known) continue;
    if (p >= 0 && several)
      declare(line, p, line.name() + "@" + station_name(line, p), {});
    else
      declare(line, p, {}, {});
  }
  if (std::find(m_known_lines.begin(), m_known_lines.end(), &line) == m_known_lines.end())
    m_known_lines.push_back(&line);
}

std::uint32_t PcapngWriter::find_interface(const bus::Line& line, int probe) {
  for (int pass = 0;; ++pass) {
    for (const LineIf& l : m_lines)
      if (l.line == &line && l.probe == probe) {
        m_last_line = &line;
        m_last_probe = probe;
        m_last_id = l.id;
        return l.id;
      }
    if (pass == 0)
      declare_taps_of(line);  // first news from this line
    else
      return declare(line, probe, {}, {});  // a tap that is no longer registered
  }
}

std::uint32_t PcapngWriter::events_interface() {
  if (m_events_if < 0)
    m_events_if = add_interface("events", "pbvbus event records v1", pcapng::LinkType::User1, 0);
  return static_cast<std::uint32_t>(m_events_if);
}

bool PcapngWriter::mark_mpi(const bus::Line& line) {
  for (const LineIf& l : m_lines)
    if (l.line == &line) return false;
  if (std::find(m_mpi_lines.begin(), m_mpi_lines.end(), &line) == m_mpi_lines.end())
    m_mpi_lines.push_back(&line);
  return true;
}

std::uint32_t PcapngWriter::add_s7_interface(std::string_view name, std::string_view description) {
  const std::uint32_t id =
      add_interface(name, description.empty() ? "S7 PDUs (exported PDU for s7comm)" : description,
                    pcapng::LinkType::UpperPdu, 0);
  m_s7_ifs.push_back(id);
  return id;
}

bool PcapngWriter::write_s7_pdu(std::uint32_t iface, bus::Ticks time,
                                std::span<const std::uint8_t> s7_pdu, const S7PduInfo& info) {
  if (!m_ok) return false;
  if (std::find(m_s7_ifs.begin(), m_s7_ifs.end(), iface) == m_s7_ifs.end()) return false;
  // Exported-PDU tags (pcapng_format.hpp): big-endian code, length, value.
  std::vector<std::uint8_t>& b = m_s7_buf;
  b.clear();
  auto be16 = [&](std::uint16_t v) {
    b.push_back(static_cast<std::uint8_t>(v >> 8));
    b.push_back(static_cast<std::uint8_t>(v));
  };
  auto be32 = [&](std::uint32_t v) {
    be16(static_cast<std::uint16_t>(v >> 16));
    be16(static_cast<std::uint16_t>(v));
  };
  const std::string_view heur = pcapng::kS7commHeuristic;
  const std::size_t heur_len = pcapng::pad4(heur.size() + 1);  // NUL, padded to 4
  be16(pcapng::kExpPduHeurProtoName);
  be16(static_cast<std::uint16_t>(heur_len));
  b.insert(b.end(), heur.begin(), heur.end());
  b.resize(b.size() + heur_len - heur.size(), 0);
  if (info.src_ip != 0 || info.dst_ip != 0) {
    be16(pcapng::kExpPduIpv4Src);
    be16(4);
    be32(info.src_ip);
    be16(pcapng::kExpPduIpv4Dst);
    be16(4);
    be32(info.dst_ip);
  }
  if (info.src_port != 0 || info.dst_port != 0) {
    be16(pcapng::kExpPduPortType);
    be16(4);
    be32(pcapng::kExpPduPortTcp);
    be16(pcapng::kExpPduSrcPort);
    be16(4);
    be32(info.src_port);
    be16(pcapng::kExpPduDstPort);
    be16(4);
    be32(info.dst_port);
  }
  be16(pcapng::kExpPduEnd);
  be16(0);
  b.insert(b.end(), s7_pdu.begin(), s7_pdu.end());
  const std::uint32_t flags = static_cast<std::uint32_t>(info.direction);
  put_epb(time, time, iface, b, flags, info.comment);
  ++m_s7_pdus;
  return true;
}

bus::Ticks PcapngWriter::earliest_in_flight() const {
  bus::Ticks t = bus::kNever;
  for (const bus::Line* l : m_known_lines) t = std::min(t, l->earliest_start_in_flight());
  return t;
}

void PcapngWriter::release(bus::Ticks upto) {
  std::size_t k = 0;
  for (; k < m_held.size() && m_held[k].ts <= upto; ++k) {
    const Held& h = m_held[k];
    std::memcpy(reserve(h.len), m_hold.data() + h.off, h.len);
    block_done();
  }
  if (k == 0) return;
  m_held.erase(m_held.begin(), m_held.begin() + static_cast<std::ptrdiff_t>(k));
  if (m_held.empty()) {
    m_hold.clear();
  } else if (m_hold.size() > kHoldReserve) {
    // Records stayed held for long (a long overlap chain): keep only what is still held.
    m_hold_spare.clear();
    for (Held& h : m_held) {
      const std::size_t off = m_hold_spare.size();
      m_hold_spare.insert(m_hold_spare.end(), m_hold.begin() + static_cast<std::ptrdiff_t>(h.off),
                          m_hold.begin() + static_cast<std::ptrdiff_t>(h.off + h.len));
      h.off = off;
    }
    std::swap(m_hold, m_hold_spare);
  }
}

void PcapngWriter::put_epb(bus::Ticks ts, bus::Ticks now, std::uint32_t if_id,
                           std::span<const std::uint8_t> data, std::uint32_t flags,
                           std::string_view comment) {
  const std::size_t opts =
      (flags ? option_size(4) : 0) + (comment.empty() ? 0 : option_size(comment.size()));
  const std::size_t total = 32 + pad4(data.size()) + (opts ? opts + 4 : 0);
  // Everything still to come starts at or after `safe`: no later record can go before this one.
  const bus::Ticks safe = std::min(now, earliest_in_flight());
  const bool direct = m_held.empty() && ts <= safe;
  std::uint8_t* p = nullptr;
  if (direct) {
    p = reserve(total);
  } else {
    const std::size_t off = m_hold.size();
    m_hold.resize(off + total);
    p = m_hold.data() + off;
    // After the records with the same or an earlier time (arrival order for equal times).
    auto pos = m_held.end();
    while (pos != m_held.begin() && std::prev(pos)->ts > ts) --pos;
    m_held.insert(pos, Held{ts, off, total});
  }
  const std::uint64_t ts_ns = timestamp_ns(ts);
  const auto len = static_cast<std::uint32_t>(data.size());
  put32(p, pcapng::kBlockEpb);
  put32(p + 4, static_cast<std::uint32_t>(total));
  put32(p + 8, if_id);
  put32(p + 12, static_cast<std::uint32_t>(ts_ns >> 32));
  put32(p + 16, static_cast<std::uint32_t>(ts_ns));
  put32(p + 20, len);
  put32(p + 24, len);
  if (!data.empty()) std::memcpy(p + 28, data.data(), data.size());
  std::size_t o = 28 + data.size();
  // Zero padding to 32 bits in one store: the block always ends with its 4-octet length, which
  // is written after this, so the store never leaves the block.
  put32(p + o, 0);
  o = pad4(o);
  if (opts) {
    if (flags) {
      std::uint8_t v[4];
      put32(v, flags);
      o += put_option(p + o, pcapng::kEpbFlags, v, 4);
    }
    if (!comment.empty())
      o += put_option(p + o, pcapng::kOptComment, comment.data(), comment.size());
    o += put_option(p + o, pcapng::kOptEndOfOpt, nullptr, 0);
  }
  put32(p + o, static_cast<std::uint32_t>(total));
  if (direct)
    block_done();
  else
    release(safe);
}

void PcapngWriter::write_frame(const bus::TapFrame& f) {
  if (!m_ok) return;
  // Fast path, the common case: an intact frame that decodes, from the line and probe of the
  // previous frame, nothing held back and nothing still on the wire that started earlier. It
  // writes what put_epb() writes for it (no options, straight into the buffer).
  if (f.flags == 0 && f.line == m_last_line && f.probe == m_last_probe && f.line != nullptr &&
      m_held.empty() && fdl::decode_once(f, m_scratch).ok() &&
      f.start <= std::min(std::max(f.start, f.end), earliest_in_flight())) {
    const std::size_t n = f.bytes.size();
    const std::size_t total = 32 + pad4(n);
    std::uint8_t* p = nullptr;
    if (m_len + total <= m_buf.size()) {  // reserve(), without the call
      p = m_buf.data() + m_len;
      m_len += total;
    } else {
      p = reserve(total);
    }
    const std::uint64_t ts_ns = timestamp_ns(f.start);
    put32(p, pcapng::kBlockEpb);
    put32(p + 4, static_cast<std::uint32_t>(total));
    put32(p + 8, m_last_id);
    put32(p + 12, static_cast<std::uint32_t>(ts_ns >> 32));
    put32(p + 16, static_cast<std::uint32_t>(ts_ns));
    put32(p + 20, static_cast<std::uint32_t>(n));
    put32(p + 24, static_cast<std::uint32_t>(n));
    if (n != 0) std::memcpy(p + 28, f.bytes.data(), n);
    put32(p + 28 + n, 0);  // padding (the block's length after it is written next)
    put32(p + total - 4, static_cast<std::uint32_t>(total));
    block_done();
    ++m_frames;
    return;
  }
  if (!f.line && m_unknown_if < 0)
    m_unknown_if = add_interface("unknown", "frames of no known line", m_opts.line_link_type, 0);
  const std::uint32_t id =
      f.line ? interface_for(*f.line, f.probe) : static_cast<std::uint32_t>(m_unknown_if);
  // An intact frame that decodes needs neither flags nor comment.
  std::uint32_t flags = 0;
  std::string_view comment;
  if (f.flags != 0 || !fdl::decode_once(f, m_scratch).ok()) {
    flags = classify_frame(f.bytes, f.flags, f.sent_len, m_comment);
    comment = m_comment;
  }
  put_epb(f.start, std::max(f.start, f.end), id, f.bytes, flags, comment);
  ++m_frames;
}

void PcapngWriter::write_event(bus::Ticks time, const EventRecord& e) {
  if (!m_ok) return;
  const std::uint32_t id = events_interface();
  const std::size_t n = encode_event(e, m_event_buf);
  put_epb(time, time, id, std::span<const std::uint8_t>(m_event_buf.data(), n), 0, {});
  ++m_events;
}

void PcapngWriter::on_line_event(const bus::LineEvent& e) {
  // Declare the line's interfaces before the events interface, so that lines keep the low
  // interface ids even when a fault (or the power-on at start) comes before the first frame.
  if (e.line && m_ok) declare_taps_of(*e.line);
  EventRecord r;
  r.category = EventCategory::Line;
  r.code = static_cast<std::uint16_t>(e.kind);
  r.line = e.line ? e.line->index() : -1;
  r.a = e.a;
  r.b = e.b;
  r.value = e.value;
  r.text = describe_line_event(e);
  write_event(e.time, r);
}

}  // namespace pbvbus::captures
