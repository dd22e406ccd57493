// libFuzzer target for the CANopen SDO server (gateways/canopen_sdo.hpp, canopen_objects.hpp,
// canopen_gateway.hpp).
//
// 1. The whole input is one SDO request: parse_sdo_request() must classify it consistently (a
//    frame shorter than 8 octets is Invalid with abort 0x05040001; a download's size is 0..4 and
//    its value fits in it).
// 2. The input is a script of frames to a gateway with one slave (node 5) over a FakeSource:
//    each step is [selector, dlc, data...]; selector & 3 picks SDO request 0x605, NMT 0x000,
//    RPDO 0x205..0x505, or "advance virtual time". Every SDO request must get at most one
//    response on 0x585, 8 octets, with a valid server command specifier and the request's index
//    and sub-index (client aborts get none); nothing may throw or touch memory it must not.
// Any violation traps, so libFuzzer reports it with the input.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <vector>

#include "fake_source.hpp"
#include "pbvbus/gateways/canopen_gateway.hpp"
#include "pbvbus/gateways/canopen_sdo.hpp"

namespace {

using namespace pbvbus;
using namespace pbvbus::gateways;

[[noreturn]] void fail(const char* why) {
  std::fprintf(stderr, "canopen sdo oracle: %s\n", why);
  __builtin_trap();
}

void check_parse(std::span<const std::uint8_t> in) {
  const auto r = canopen::parse_sdo_request(in);
  if (in.size() < 8 && r.kind != canopen::SdoRequestKind::Invalid) fail("short frame accepted");
  if (r.kind == canopen::SdoRequestKind::Invalid && r.abort != canopen::kAbortCommandSpecifier)
    fail("invalid request without abort 0x05040001");
  if (r.kind == canopen::SdoRequestKind::Download) {
    if (r.size > 4) fail("download size above 4");
    if (r.size && r.size < 4 && (r.value >> (8 * r.size)) != 0) fail("value wider than size");
  }
}

void run_script(std::span<const std::uint8_t> in) {
  bus::Scheduler sched;
  gateways::test::FakeSource src;
  SourceModule in_mod, out_mod;
  in_mod.name = "in";
  in_mod.in_len = 10;
  out_mod.name = "out";
  out_mod.out_len = 9;
  src.add_slave(5, 0x0A03, {in_mod, out_mod});
  CanHub hub;
  std::vector<CanFrame> responses;
  const auto tool = hub.add_port("tool", [&](const CanFrame& f, bus::Ticks) {
    if (f.id == 0x585) responses.push_back(f);
  });
  CanopenGateway gw(sched, src, hub);
  gw.start(0);
  sched.run_until(0);

  std::size_t i = 0;
  while (i + 2 <= in.size()) {
    const std::uint8_t sel = in[i];
    CanFrame f;
    f.dlc = static_cast<std::uint8_t>(in[i + 1] % 9);
    i += 2;
    for (std::size_t k = 0; k < f.dlc; ++k) f.data[k] = i + k < in.size() ? in[i + k] : 0;
    i += f.dlc;
    switch (sel & 3) {
      case 0: {
        f.id = 0x605;
        const auto before = responses.size();
        hub.send(tool, f, sched.now());
        const auto req = canopen::parse_sdo_request({f.data.data(), f.dlc});
        const std::size_t want = req.kind == canopen::SdoRequestKind::ClientAbort ? 0 : 1;
        if (responses.size() != before + want) fail("not exactly one response per request");
        if (want == 0) break;
        const CanFrame& r = responses.back();
        const std::uint8_t cs = r.data[0];
        const bool upload = cs == 0x43 || cs == 0x47 || cs == 0x4B || cs == 0x4F;
        if (r.dlc != 8 || !(upload || cs == 0x60 || cs == 0x80)) fail("bad response octet 0");
        const std::uint16_t index = static_cast<std::uint16_t>(r.data[1] | (r.data[2] << 8));
        if (index != req.index || r.data[3] != req.sub) fail("multiplexer not echoed");
        if (cs == 0x80 && req.kind != canopen::SdoRequestKind::Invalid && r.data[7] == 0)
          fail("abort without a code");
        break;
      }
      case 1: f.id = 0x000; hub.send(tool, f, sched.now()); break;
      case 2: f.id = 0x205 + 0x100u * ((sel >> 2) & 3); hub.send(tool, f, sched.now()); break;
      default: sched.run_until(sched.now() + (sel >> 2) * bus::kTicksPerMs); break;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  check_parse(in);
  run_script(in);
  return 0;
}
