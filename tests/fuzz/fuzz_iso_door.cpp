// libFuzzer target for the ISO-on-TCP door's input (gateways/iso_on_tcp): a client's byte
// stream, in chunks, into an IsoSession routed to a LocalCpuRouter (one CPU, DB1 and DB2) — TPKT
// reassembly, COTP CR/DT/DR/ER handling and S7 dispatch into the CPU's S7 server. Octet 0 picks
// the chunk size and the queue bound; the rest is the stream. Invariants (a broken one traps):
// everything the session sends is whole TPKTs (version 3, length field = octets), nothing is
// sent after the session finished, the session finishes at most once, outstanding jobs never
// exceed the AmQ in force, waiting jobs never exceed the bound.
//   build-fuzz/bin/fuzz_iso_door -max_total_time=60 <scratch dir> tests/fuzz/corpus/iso_door
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>

#include "pbvbus/iso_on_tcp/iso_session.hpp"
#include "pbvbus/iso_on_tcp/local_cpu_router.hpp"

namespace {

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "iso door invariant broken: %s\n", what);
    __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pbvbus;
  if (size == 0) return 0;
  const std::size_t chunk = 1 + (data[0] & 0x1F);
  iso_on_tcp::SessionLimits limits;
  limits.max_queued_jobs = 1 + (data[0] >> 5);
  std::span<const std::uint8_t> in(data + 1, size - 1);

  s7cpu::CpuMemory memory;
  memory.create_db(1, 64);
  memory.create_db(2, 300);
  const s7cpu::CpuInfo info;
  iso_on_tcp::LocalCpu cpu;
  cpu.memory = &memory;
  cpu.info = &info;
  cpu.limits = {2, 2, 240};
  iso_on_tcp::LocalCpuRouter router(cpu);

  int finishes = 0;
  bool sent_after_finish = false;
  iso_on_tcp::IsoSession::Hooks hooks;
  hooks.send = [&](std::span<const std::uint8_t> o) {
    check(o.size() >= 7, "TPKT shorter than 7 octets");
    check(o[0] == 3 && o[1] == 0, "TPKT header");
    check(((std::size_t{o[2]} << 8) | o[3]) == o.size(), "TPKT length field");
    if (finishes > 0) sent_after_finish = true;
  };
  hooks.finish = [&](iso_on_tcp::SessionEnd, const std::string&) { ++finishes; };
  iso_on_tcp::IsoSession session(router, limits, std::move(hooks), 1, 1);
  while (!in.empty()) {
    const std::size_t n = chunk < in.size() ? chunk : in.size();
    session.feed(in.first(n));
    in = in.subspan(n);
    check(session.in_flight() <= session.amq(), "more jobs outstanding than AmQ");
    check(session.queued() <= limits.max_queued_jobs, "queue past its bound");
  }
  check(finishes <= 1, "finished twice");
  check(!sent_after_finish, "sent after finish");
  return 0;
}
