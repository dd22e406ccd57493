// Untrusted frames into an MPI station (a PG attached through a pty may send anything): 20 000
// seeded frames addressed to a CPU's MPI station, driven by hand through a RecordingPort (the
// station is powered and listening, never holding the token). Each frame is an SD2 SRD with SAPs
// whose DU is a mutated MPI PDU (connect request, connection ack, data with a mutated S7 PDU,
// data ack, disconnect, or noise). The oracle, independent of the station's code: every request
// gets exactly one reply, min TSDR after its end, and it is SC (E5) or a short SD1 status frame
// `10 SA DA FC FCS 16` with status UE, RR or RS (§B.3, docs/mpi.md decision 4), with a correct
// FCS; the pool never holds more than its connections. Also built into sanitize_devices_mpi_station.

#include <gtest/gtest.h>

#include <random>

#include "mpi_line_helpers.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "recording_port.hpp"

namespace pbvbus::mpi_station::test {
namespace {

TEST(MpiReceivedFrames, SeededMutationsGetScOrAStatusReply) {
  s7cpu::CpuMemory memory;
  memory.create_db(1, 64);
  s7cpu::CpuInfo info;
  S7CpuSessionFactory factory(memory, info);
  MpiStationConfig c;
  c.address = 2;
  c.pool.max_connections = 3;
  MpiStation cpu(c, &factory);
  pbvbus::test::RecordingPort port(bus::Baud::k187_5);
  port.bind(cpu);
  cpu.on_power_on(0);

  std::mt19937 rng(20261128);
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  const Bytes setup = bytes_from_hex("32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 03 C0");
  const Bytes read = bytes_from_hex("32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00");
  const bus::Ticks bit = port.bit_ticks();
  bus::Ticks t = 0;
  int sc = 0, status = 0;
  std::uint8_t fcb[128] = {};
  std::uint8_t nr = 0;         // the data messages' numbers, mostly in sequence
  std::uint8_t cur_sap = 0x14;  // the CPU's SAP of the latest connection it accepted
  for (int i = 0; i < 20'000; ++i) {
    if (i % 400 == 399) {
      // The station never holds the token here, so its frames never get their FDL results and
      // their SAPs stay taken (docs/mpi.md decision 5): a power cycle now and then starts afresh.
      cpu.on_power_off(t);
      cpu.on_power_on(t);
      (void)cpu.take_events();
      cur_sap = 0x14;
    }
    Bytes du;
    // Mostly the frames of a PG's session (connect, connection ack, data in sequence, acks),
    // now and then a disconnect, a stray confirm or noise.
    const int w = pick(20);
    const int kind = w < 2 ? 0 : w < 4 ? 1 : w < 13 ? 2 : w < 16 ? 3 : w == 16 ? 4 : w == 17 ? 5 : 6;
    switch (kind) {
      case 0:
        du = bytes_from_hex("E0 04 00 80 00 02 00 02 01 00 01 00");
        break;
      case 1: du = {0x05, 0x01}; break;
      case 2: {
        du = {0xF1, pick(8) ? nr++ : static_cast<std::uint8_t>(rng())};
        const Bytes& s7 = pick(2) ? setup : read;
        du.insert(du.end(), s7.begin(), s7.end());
        break;
      }
      case 3: du = {0xB0, 0x01, static_cast<std::uint8_t>(pick(4))}; break;
      case 4: du = {0x80}; break;
      case 5: du = {0xD0, 0x01}; break;
      default:
        du.resize(static_cast<std::size_t>(1 + pick(40)));
        for (auto& b : du) b = static_cast<std::uint8_t>(rng());
    }
    // Mutations (half of the frames): change, cut or extend.
    const int m = pick(6);
    if (m == 0 && !du.empty()) du[static_cast<std::size_t>(pick(static_cast<int>(du.size())))] ^= static_cast<std::uint8_t>(1 + pick(255));
    if (m == 1 && du.size() > 1) du.resize(static_cast<std::size_t>(1 + pick(static_cast<int>(du.size()) - 1)));
    if (m == 2) du.push_back(static_cast<std::uint8_t>(rng()));
    if (du.size() > 244) du.resize(244);

    fdl::FrameSpec spec;
    const std::uint8_t sa = static_cast<std::uint8_t>(pick(5) == 0 ? 3 + pick(10) : 0);
    spec.da = 2;
    spec.sa = sa;
    // FCB as an initiator would run it (§C.6), sometimes a repeat or a first frame again.
    const int f = pick(10);
    if (f == 0 || fcb[sa] == 0) {
      spec.fc = fdl::make_request_fc(fdl::RequestFn::SrdHigh, false, true);
      fcb[sa] = 1;
    } else {
      if (f != 1) fcb[sa] = fcb[sa] == 1 ? 2 : 1;  // f == 1: a repeat with the same FCB
      spec.fc = fdl::make_request_fc(fdl::RequestFn::SrdHigh, true, fcb[sa] == 1);
    }
    // DSAP: 0 for connect requests, the CPU's first SAPs otherwise, mostly; sometimes any.
    if (pick(4) == 0) {
      spec.dsap = static_cast<std::uint8_t>(pick(64));
    } else {
      spec.dsap = static_cast<std::uint8_t>(kind == 0 ? 0 : cur_sap);
    }
    spec.ssap = static_cast<std::uint8_t>(pick(4) ? 0x14 : pick(64));
    spec.data = du;
    fdl::Frame frame;
    ASSERT_EQ(fdl::encode(spec, frame), fdl::EncodeError::None);

    const bus::Ticks start = t + 100 * bit;
    bus::RxFrame rx;
    rx.bytes = frame.bytes();
    rx.start = start;
    rx.end = start + static_cast<bus::Ticks>(frame.len) * 11 * bit;
    rx.idle_before = 100 * bit;
    port.set_now(rx.end);
    port.clear();
    cpu.on_frame(rx);
    t = rx.end + 400 * bit;

    ASSERT_EQ(port.transmit_count(), 1u) << i << ": " << to_hex(frame.bytes());
    const auto& reply = port.last();
    EXPECT_EQ(reply.start, rx.end + 20 * bit) << i;  // min TSDR
    if (reply.bytes == Bytes{0xE5}) {
      ++sc;
    } else {
      ++status;
      ASSERT_EQ(reply.bytes.size(), 6u) << i << ": " << to_hex(reply.bytes);
      EXPECT_EQ(reply.bytes[0], 0x10);
      EXPECT_EQ(reply.bytes[1], sa);
      EXPECT_EQ(reply.bytes[2], 2);
      const std::uint8_t st = reply.bytes[3] & 0x0F;
      EXPECT_TRUE(st == 0x1 || st == 0x2 || st == 0x3) << i << ": " << to_hex(reply.bytes);
      EXPECT_EQ(reply.bytes[4], static_cast<std::uint8_t>(reply.bytes[1] + reply.bytes[2] + reply.bytes[3]));
      EXPECT_EQ(reply.bytes[5], 0x16);
    }
    ASSERT_LE(cpu.server_connections(), 3u);
    for (const auto& e : cpu.take_events()) {
      if (e.kind == EventKind::Accepted) {
        cur_sap = e.local_sap;
        nr = 0;
      }
    }
  }
  // Both outcomes were reached, and the station took connections and answered jobs.
  EXPECT_GT(sc, 1000);
  EXPECT_GT(status, 1000);
  EXPECT_GT(cpu.stats().connects_accepted, 100u);
  EXPECT_GT(cpu.stats().pdus_received, 50u);  // 96 with this seed
  EXPECT_GT(cpu.stats().pdus_sent, 20u);      // answers queued: 49
  EXPECT_GT(cpu.stats().connects_refused, 0u);
}

}  // namespace
}  // namespace pbvbus::mpi_station::test
