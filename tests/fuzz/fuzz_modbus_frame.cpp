// libFuzzer target for the Modbus framing of the doors (gateways/modbus_frame.hpp).
//
// The input is an arbitrary octet stream as a serial line or a TCP connection would carry it.
// Oracles (any violation traps, so libFuzzer reports the input):
//  - RTU framer: every delivered frame has a good CRC (checked with an independent bitwise
//    CRC), unit = first octet, PDU = frame minus unit and CRC, at most 256 octets, and a frame
//    whose function code has a length rule is exactly that long; at most 256 octets are ever
//    pending; after silence() nothing is; every octet fed is either in a delivered frame or
//    counted as dropped; feeding the stream in chunks (sizes taken from the input) delivers the
//    same frames as feeding it whole.
//  - MBAP: a header decode_mbap() accepts re-encodes to the same 7 octets, and its PDU (when
//    present) re-encoded as a TCP ADU decodes to the same header.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <span>
#include <vector>

#include "pbvbus/gateways/modbus_frame.hpp"

namespace {

using namespace pbvbus::gateways;

[[noreturn]] void fail(const char* why) {
  std::fprintf(stderr, "modbus frame oracle: %s\n", why);
  __builtin_trap();
}

std::uint16_t crc_bitwise(std::span<const std::uint8_t> b) {
  unsigned crc = 0xFFFF;
  for (auto o : b) {
    crc ^= o;
    for (int i = 0; i < 8; ++i) crc = (crc & 1u) ? (crc >> 1) ^ 0xA001u : crc >> 1;
  }
  return static_cast<std::uint16_t>(crc);
}

struct Run {
  std::vector<std::vector<std::uint8_t>> frames;
  std::size_t octets = 0;
  RtuFramer::Stats stats;
};

Run frame(std::span<const std::uint8_t> s, std::span<const std::uint8_t> chunking) {
  Run r;
  RtuFramer f;
  RtuFramer::Sink sink = [&](const RtuFrame& fr) {
    if (fr.adu.size() < 4 || fr.adu.size() > kModbusRtuMaxAdu) fail("frame size");
    if (fr.unit != fr.adu[0] || fr.pdu.size() + 3 != fr.adu.size() ||
        fr.pdu.data() != fr.adu.data() + 1)
      fail("frame parts");
    const std::uint16_t crc = crc_bitwise(fr.adu.first(fr.adu.size() - 2));
    if (fr.adu[fr.adu.size() - 2] != (crc & 0xFF) || fr.adu.back() != (crc >> 8))
      fail("bad CRC delivered");
    if (const auto want = rtu_request_length(fr.adu); want && *want != 0 && *want != fr.adu.size())
      fail("length rule");
    r.frames.emplace_back(fr.adu.begin(), fr.adu.end());
    r.octets += fr.adu.size();
  };
  std::size_t i = 0, k = 0;
  while (i < s.size()) {
    std::size_t n = s.size() - i;
    if (!chunking.empty()) n = std::min<std::size_t>(n, 1 + chunking[k++ % chunking.size()] % 64);
    f.feed(s.subspan(i, n), sink);
    if (f.pending() > kModbusRtuMaxAdu) fail("pending beyond one frame");
    i += n;
  }
  f.silence(sink);
  if (f.pending() != 0) fail("pending after silence");
  r.stats = f.stats();
  if (r.octets + r.stats.dropped_octets != s.size()) fail("octets lost or invented");
  if (r.stats.frames != r.frames.size()) fail("frame count");
  return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  // The first 4 octets (if any) choose chunk sizes; the whole input is the stream.
  const auto chunking = in.first(std::min<std::size_t>(4, in.size()));
  const Run whole = frame(in, {});
  const Run chunked = frame(in, chunking);
  if (whole.frames != chunked.frames) fail("chunking changed the frames");

  const MbapDecoded d = decode_mbap(in);
  if (d.ok()) {
    std::array<std::uint8_t, kMbapHeaderLen> h{};
    encode_mbap(d.header, h);
    if (std::memcmp(h.data(), data, kMbapHeaderLen) != 0) fail("MBAP round trip");
    if (size >= d.adu_len()) {
      std::array<std::uint8_t, kModbusTcpMaxAdu> adu{};
      const std::size_t n = encode_tcp_adu(d.header.transaction_id, d.header.unit,
                                           in.subspan(kMbapHeaderLen, d.pdu_len()), adu);
      if (n != d.adu_len() || std::memcmp(adu.data(), data, n) != 0) fail("TCP ADU round trip");
      const MbapDecoded e = decode_mbap(std::span(adu).first(n));
      if (!e.ok() || !(e.header == d.header)) fail("TCP ADU decode");
    }
  } else if (size >= kMbapHeaderLen && d.error == MbapError::Short) {
    fail("short with 7 octets");
  }
  return 0;
}
