// libFuzzer target for the MPI connection-layer PDU decoder (protocol-facts.md §H.3) and the
// CPU side's connection pool behind it.
//
// 1. The input is one MPI PDU: decode() must not read outside it; if it accepts it, encode() of
//    the result gives the identical octets (the codec is canonical) and decodes to the same
//    fields.
// 2. The input is also a script for a ConnectionPool (max 2 connections): frames from peers on
//    any SAP pair, FDL results, time steps. Whatever comes, the pool never holds more than its
//    maximum, every frame it sends carries a PDU that decodes, and a deadline is never in the
//    past after on_timer().
// Any violation traps, so libFuzzer reports it with the input.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <span>

#include "pbvbus/mpi/connection_pool.hpp"
#include "pbvbus/mpi/pdu.hpp"

namespace {

[[noreturn]] void fail(const char* why) {
  std::fprintf(stderr, "mpi oracle: %s\n", why);
  __builtin_trap();
}

void check_codec(std::span<const std::uint8_t> in) {
  using namespace pbvbus::mpi;
  Pdu p;
  if (decode(in, p) != DecodeError::None) return;
  PduBuffer b;
  if (encode(p, b) != EncodeError::None) fail("an accepted PDU does not encode");
  if (b.len != in.size() || std::memcmp(b.buf.data(), in.data(), in.size()) != 0) {
    fail("encode(decode(x)) != x");
  }
  Pdu q;
  if (decode(b.bytes(), q) != DecodeError::None || q.type != p.type || q.message_number != p.message_number ||
      q.connect_params != p.connect_params || q.data.size() != p.data.size()) {
    fail("decode(encode(p)) != p");
  }
}

void check_outbox(const pbvbus::mpi::Outbox& out) {
  for (const auto& f : out.frames) {
    pbvbus::mpi::Pdu p;
    if (pbvbus::mpi::decode(f.pdu.bytes(), p) != pbvbus::mpi::DecodeError::None) fail("sent an invalid PDU");
    if (p.type != f.type) fail("frame type differs from its PDU");
  }
}

void run_pool(std::span<const std::uint8_t> in) {
  using namespace pbvbus::mpi;
  PoolConfig config;
  config.max_connections = 2;
  config.timing = ConnectionTiming{1000, 1000};
  ConnectionPool pool(config);
  Outbox out;
  pbvbus::bus::Ticks now = 0;
  std::size_t i = 0;
  while (i < in.size()) {
    const std::uint8_t op = in[i++];
    switch (op % 4) {
      case 0: {  // frame: peer, dsap, ssap, len, PDU
        if (in.size() - i < 4) return;
        const std::uint8_t peer = in[i] & 0x7F;
        const std::uint8_t dsap = in[i + 1] & 0x3F;
        const std::uint8_t ssap = in[i + 2] & 0x3F;
        const std::size_t len = std::min<std::size_t>(in[i + 3], in.size() - i - 4);
        pool.on_frame(now, Received{peer, dsap, ssap, in.subspan(i + 4, len)}, out);
        i += 4 + len;
        break;
      }
      case 1:  // FDL result for a SAP
        if (i >= in.size()) return;
        pool.on_fdl_result(now, in[i] & 0x3F, static_cast<FdlResult>((op >> 2) % 3), out);
        ++i;
        break;
      case 2:  // time passes
        now += (op >> 2) * 64;
        pool.on_timer(now, out);
        if (pool.deadline() && *pool.deadline() <= now) fail("deadline in the past after on_timer");
        break;
      case 3: {  // the CPU's user sends data or disconnects
        if (i >= in.size()) return;
        const std::uint8_t sap = in[i++] & 0x3F;
        if (op & 4) {
          pool.disconnect(now, sap, out);
        } else {
          pool.send_data(now, sap, in.subspan(i, std::min<std::size_t>(in.size() - i, 8)), out);
        }
        break;
      }
    }
    if (pool.open_connections() > config.max_connections) fail("more connections than the maximum");
    check_outbox(out);
    out.clear();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  check_codec(in);
  run_pool(in);
  return 0;
}
