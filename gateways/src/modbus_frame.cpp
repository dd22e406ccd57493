#include "pbvbus/gateways/modbus_frame.hpp"

#include <algorithm>
#include <cstring>

namespace pbvbus::gateways {

std::string_view to_string(MbapError e) {
  switch (e) {
    case MbapError::None:
      return "ok";
    case MbapError::Short:
      return "short header";
    case MbapError::ProtocolId:
      return "protocol id not 0";
    case MbapError::LengthTooSmall:
      return "length below 2";
    case MbapError::LengthTooLarge:
      return "length above 254";
  }
  return "?";
}

MbapDecoded decode_mbap(std::span<const std::uint8_t> b) {
  MbapDecoded d;
  if (b.size() < kMbapHeaderLen) return d;
  d.header.transaction_id = static_cast<std::uint16_t>(b[0] << 8 | b[1]);
  d.header.protocol_id = static_cast<std::uint16_t>(b[2] << 8 | b[3]);
  d.header.length = static_cast<std::uint16_t>(b[4] << 8 | b[5]);
  d.header.unit = b[6];
  if (d.header.protocol_id != 0)
    d.error = MbapError::ProtocolId;
  else if (d.header.length < 2)
    d.error = MbapError::LengthTooSmall;
  else if (d.header.length > kModbusMaxPdu + 1)
    d.error = MbapError::LengthTooLarge;
  else
    d.error = MbapError::None;
  return d;
}

void encode_mbap(const MbapHeader& h, std::span<std::uint8_t, kMbapHeaderLen> out) {
  out[0] = static_cast<std::uint8_t>(h.transaction_id >> 8);
  out[1] = static_cast<std::uint8_t>(h.transaction_id);
  out[2] = static_cast<std::uint8_t>(h.protocol_id >> 8);
  out[3] = static_cast<std::uint8_t>(h.protocol_id);
  out[4] = static_cast<std::uint8_t>(h.length >> 8);
  out[5] = static_cast<std::uint8_t>(h.length);
  out[6] = h.unit;
}

std::size_t encode_tcp_adu(std::uint16_t tid, std::uint8_t unit, std::span<const std::uint8_t> pdu,
                           std::span<std::uint8_t> out) {
  const std::size_t n = kMbapHeaderLen + pdu.size();
  if (pdu.empty() || pdu.size() > kModbusMaxPdu || out.size() < n) return 0;
  encode_mbap({tid, 0, static_cast<std::uint16_t>(pdu.size() + 1), unit},
              out.first<kMbapHeaderLen>());
  std::memcpy(out.data() + kMbapHeaderLen, pdu.data(), pdu.size());
  return n;
}

namespace {
// Table-driven CRC-16/MODBUS (reflected poly 0xA001): the table is the bitwise algorithm run
// once per octet value, so both give the same result; the door computes a CRC per frame.
constexpr std::array<std::uint16_t, 256> make_crc_table() {
  std::array<std::uint16_t, 256> t{};
  for (unsigned v = 0; v < 256; ++v) {
    unsigned crc = v;
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1u) ? (crc >> 1) ^ 0xA001u : crc >> 1;
    t[v] = static_cast<std::uint16_t>(crc);
  }
  return t;
}
constexpr auto kCrcTable = make_crc_table();
}  // namespace

std::uint16_t crc16_modbus(std::span<const std::uint8_t> bytes) {
  unsigned crc = 0xFFFF;
  for (std::uint8_t b : bytes) crc = (crc >> 8) ^ kCrcTable[(crc ^ b) & 0xFFu];
  return static_cast<std::uint16_t>(crc);
}

std::size_t encode_rtu_adu(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                           std::span<std::uint8_t> out) {
  const std::size_t n = 1 + pdu.size() + 2;
  if (pdu.empty() || pdu.size() > kModbusMaxPdu || out.size() < n) return 0;
  out[0] = unit;
  std::memcpy(out.data() + 1, pdu.data(), pdu.size());
  const std::uint16_t crc = crc16_modbus(out.first(1 + pdu.size()));
  out[n - 2] = static_cast<std::uint8_t>(crc & 0xFF);
  out[n - 1] = static_cast<std::uint8_t>(crc >> 8);
  return n;
}

std::optional<std::size_t> rtu_request_length(std::span<const std::uint8_t> head) {
  if (head.size() < 2) return std::size_t{0};
  switch (head[1]) {
    case 1:
    case 2:
    case 3:
    case 4:
    case 5:
    case 6:
    case 8:
      return std::size_t{8};
    case 7:
    case 11:
    case 12:
    case 17:
      return std::size_t{4};
    case 15:
    case 16:
      if (head.size() < 7) return std::size_t{0};
      return std::size_t{7} + head[6] + 2;
    case 22:
      return std::size_t{10};
    case 23:
      if (head.size() < 11) return std::size_t{0};
      return std::size_t{11} + head[10] + 2;
    case 24:
      return std::size_t{6};
    case 43:
      return std::size_t{7};
    default:
      return std::nullopt;
  }
}

void RtuFramer::feed(std::span<const std::uint8_t> bytes, const Sink& sink) {
  while (!bytes.empty()) {
    // scan() leaves at most kModbusRtuMaxAdu octets, so there is always room for more.
    const std::size_t n = std::min(bytes.size(), m_buf.size() - m_len);
    std::memcpy(m_buf.data() + m_len, bytes.data(), n);
    m_len += n;
    bytes = bytes.subspan(n);
    scan(sink);
  }
}

void RtuFramer::scan(const Sink& sink) {
  while (m_len >= 2) {
    const std::span<const std::uint8_t> head(m_buf.data(), m_len);
    const auto want = rtu_request_length(head);
    if (!want) {  // unknown FC: silence ends it, unless it outgrows any frame
      if (m_len <= kModbusRtuMaxAdu) return;
      ++m_stats.overlong;
      drop_front(1);
      continue;
    }
    if (*want == 0) return;  // the byte count is not here yet
    if (*want > kModbusRtuMaxAdu) {
      ++m_stats.overlong;
      drop_front(1);
      continue;
    }
    if (m_len < *want) return;
    if (deliver_if_good(*want, sink)) continue;
    ++m_stats.bad_crc;
    drop_front(1);
  }
}

void RtuFramer::silence(const Sink& sink) {
  bool lost = false;
  while (m_len > 0) {
    const std::span<const std::uint8_t> head(m_buf.data(), m_len);
    if (m_len >= 2 && !rtu_request_length(head) && deliver_if_good(m_len, sink)) break;
    // Not a frame: give up its first octet and look for a complete frame in the rest.
    lost = true;
    drop_front(1);
    scan(sink);
  }
  if (lost) ++m_stats.incomplete;
}

bool RtuFramer::deliver_if_good(std::size_t len, const Sink& sink) {
  if (len < 4 || len > kModbusRtuMaxAdu || len > m_len) return false;
  const std::uint16_t crc = crc16_modbus(std::span<const std::uint8_t>(m_buf.data(), len - 2));
  if (m_buf[len - 2] != (crc & 0xFF) || m_buf[len - 1] != (crc >> 8)) return false;
  ++m_stats.frames;
  RtuFrame f;
  f.unit = m_buf[0];
  f.pdu = std::span<const std::uint8_t>(m_buf.data() + 1, len - 3);
  f.adu = std::span<const std::uint8_t>(m_buf.data(), len);
  if (sink) sink(f);
  std::memmove(m_buf.data(), m_buf.data() + len, m_len - len);
  m_len -= len;
  return true;
}

void RtuFramer::drop_front(std::size_t n) {
  n = std::min(n, m_len);
  std::memmove(m_buf.data(), m_buf.data() + n, m_len - n);
  m_len -= n;
  m_stats.dropped_octets += n;
}

}  // namespace pbvbus::gateways
