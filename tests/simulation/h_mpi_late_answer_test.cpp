// S7 jobs of an MPI client held across an H update (000 L1673-1680: "associated communication
// jobs are not executed during the update. They are stored and caught up on"; docs/h-sfc90.md
// "Communication jobs held by the update"): a PG on the MPI line of the H CPUs.
//
// The run (pair defaults: startup 1 s, link-up 2 s, update 75 ms + 0.7 ms x 100 KB = 145 ms):
//   0 s       both CPUs on: CPU 0 (MPI 2) master STARTUP, CPU 1 (MPI 3) standby in STOP
//   0.2 s     the PG (MPI 0) connects to MPI 2 (before the link-up: R8 refuses from then on)
//   1 s       CPU 0 RUN (Solo), CPU 1 LINK-UP
//   3 s       UPDATE: t1 = 3.000 s (interrupts and communication held)
//   3.145 s   t5: Redundant, the held jobs are answered (in RUN-R)
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kT1 = 3000 * kMs;
constexpr bus::Ticks kT5 = 3145 * kMs;  // 1 s + 2 s + (75 + 0.7 x 100) ms
// Bounds in bit times at 187.5 kbit/s (5.33 us each; mpi_bus_params: TSL 415, TID1 37, min
// TSDR 20). One rotation of the ring of three (PG 0, CPU 2, CPU 3), each station passing the
// token (3 octets x 11 = 33 bits + TID1 37) after at most one unanswered GAP poll (6 octets =
// 66 bits + TSL 415): R = 3 x 551 = 1653 bits. The SZL W#16#0424 answer's frame: SD2 with LE =
// DA SA FC DSAP SSAP 5 + F1 nr 2 + the 54-octet PDU (userdata header 10, parameters 12, data 32:
// FF 09 00 1C, the SZL header of 8 octets and one 20-octet record) = 61 = 0x3D, so 4 + 61 + 2 =
// 67 octets = 737 bits; its SC (min TSDR 20 + 11) 31 bits.
//  - The first answer is queued at t5 and leaves at the CPU's next token: <= R + 737 + 31 =
//    2421 bits = 12.9 ms -> kFirst = 15 ms.
//  - The second waits for the PG's ack of the first (at the PG's next token, <= R, 14 octets =
//    154 bits + SC 31), then for the CPU's next token (<= R): <= 2421 + 2 x 1653 + 185 + 768 =
//    6680 bits = 35.6 ms -> kSecond = 40 ms (also the bound for a job answered at once: the
//    job at the PG's next token, the ack and answer at the CPU's next one).
constexpr bus::Ticks kFirst = 15 * kMs;
constexpr bus::Ticks kSecond = 40 * kMs;

const std::string kText = R"(name: "late-mpi"
duration: "4s"
line { name: "MPI" kind: MPI }
h_system {
  name: "H-CPU"
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } mpi { line: "MPI" } }
  work_memory_db_kb: 100
}
mpi_station { role: PG line: "MPI" }
)";

std::vector<std::uint8_t> hex(std::string_view s) {
  std::string clean;
  for (const char ch : s)
    if (ch != '|') clean.push_back(ch);
  return test::bytes_from_hex(clean);
}
// Setup Communication (protocol-facts.md §H.4): reference 00 01, AmQ 1/1, PDU 240 (00 F0).
const std::vector<std::uint8_t> kSetup = hex("32 01 00 00 00 01 00 08 00 00 | F0 00 00 01 00 01 00 F0");
// Userdata (32 07), reference 00 14 / 00 15, param 8, data 8: CPU functions (request 0x44),
// subfunction 01 Read SZL; data FF 09 length 4, SZL-ID 04 24, index 00 00 (docs/s7.md). The
// answer's octet 37 is the SZL 0424 record's bzu_id: 09 = RUN-R, 08 = RUN (Solo).
const std::vector<std::uint8_t> kSzl0424a =
    hex("32 07 00 00 00 14 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04 04 24 00 00");
const std::vector<std::uint8_t> kSzl0424b =
    hex("32 07 00 00 00 15 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04 04 24 00 00");

struct PgRun {
  std::unique_ptr<Simulation> sim;
  test::FrameRecorder rec;
  mpi_station::MpiStation* pg = nullptr;
  std::optional<mpi_station::Handle> h;
  std::vector<mpi_station::StationEvent> events;

  explicit PgRun(const std::string& text = kText) {
    auto loaded = parse_scenario(text, "late-mpi.textproto");
    if (!loaded.ok()) throw std::runtime_error(loaded.errors.at(0).str());
    sim = std::make_unique<Simulation>(*loaded.plan);
    sim->line(0).add_tap(rec);
    pg = &sim->mpi_client(0).station();
    // The test drives the PG's station itself (the node has no reads to make).
    pg->set_event_handler([this](const mpi_station::StationEvent& e) { events.push_back(e); });
    sim->start();
  }
  std::vector<mpi_station::StationEvent> replies() const {
    std::vector<mpi_station::StationEvent> out;
    for (const auto& e : events)
      if (e.kind == mpi_station::EventKind::Reply) out.push_back(e);
    return out;
  }
  /// Connects to `cpu` (CPU 0 at MPI 2) at 0.2 s and sets up communication (answered at once).
  void connect(std::uint8_t cpu = 2) {
    sim->run_until(200 * kMs);
    h = pg->open(cpu);
    ASSERT_TRUE(h);
    sim->run_until(600 * kMs);
    ASSERT_EQ(pg->state(*h), mpi::State::Connected);
    ASSERT_EQ(pg->submit(*h, kSetup), mpi::RequestError::None);
    sim->run_until(800 * kMs);
    ASSERT_EQ(replies().size(), 1u);
  }
  /// Index of the first data message (F1) from CPU 2 (SA 82) to the PG (DA 80) starting at or
  /// after `from`; rec.size() if none.
  std::size_t cpu_data_message(bus::Ticks from) const {
    for (std::size_t i = 0; i < rec.size(); ++i) {
      const auto& f = rec.frame(i);
      if (f.start < from || f.bytes.size() < 10 || f.bytes[0] != 0x68) continue;
      if (f.bytes[4] == 0x80 && f.bytes[5] == 0x82 && f.bytes[9] == 0xF1) return i;
    }
    return rec.size();
  }
};

TEST(HMpiLateAnswer, PgJobsDuringTheUpdateAreAnsweredAfterT5InArrivalOrderInRunR) {
  PgRun r;
  ASSERT_NO_FATAL_FAILURE(r.connect());
  r.sim->run_until(kT1 + 50 * kMs);
  ASSERT_TRUE(r.sim->h_system(0).model().pair().interrupts_held());
  const std::size_t before = r.replies().size();
  ASSERT_EQ(r.pg->submit(*r.h, kSzl0424a), mpi::RequestError::None);
  ASSERT_EQ(r.pg->submit(*r.h, kSzl0424b), mpi::RequestError::None);
  // Both jobs reach the CPU and are acked by the MPI layer (the PG sends the second after the
  // first's data ack); the model holds them.
  r.sim->run_until(kT1 + 100 * kMs);
  EXPECT_EQ(r.pg->queued(*r.h), 0u);
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 2u);
  r.sim->run_until(kT5 - 1);
  EXPECT_EQ(r.replies().size(), before);
  EXPECT_EQ(r.cpu_data_message(kT1), r.rec.size());  // no answer on the wire before t5
  EXPECT_EQ(r.pg->state(*r.h), mpi::State::Connected);  // held 145 ms: the connection stays

  r.sim->run_until(kT5 + kSecond);
  const auto rs = r.replies();
  ASSERT_EQ(rs.size(), before + 2);
  const auto& a = rs[before];
  const auto& b = rs[before + 1];
  EXPECT_GT(a.at, kT5);
  EXPECT_LE(a.at, kT5 + kFirst);
  EXPECT_LE(b.at, kT5 + kSecond);
  const std::size_t first = r.cpu_data_message(kT1);
  ASSERT_LT(first, r.rec.size());
  EXPECT_GE(r.rec.frame(first).start, kT5);
  // In arrival order, each with its job's PDU reference (octets 4-5), both in RUN-R (09).
  ASSERT_GT(a.pdu.size(), 37u);
  ASSERT_GT(b.pdu.size(), 37u);
  EXPECT_EQ(a.pdu[0], 0x32);
  EXPECT_EQ(a.pdu[1], 0x07);
  EXPECT_EQ(a.pdu[4], 0x00);
  EXPECT_EQ(a.pdu[5], 0x14);
  EXPECT_EQ(b.pdu[5], 0x15);
  EXPECT_EQ(a.pdu[37], 0x09);
  EXPECT_EQ(b.pdu[37], 0x09);
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 0u);

  // After the update a job is answered at once again (within kSecond).
  r.sim->run_until(kT5 + 100 * kMs);
  ASSERT_EQ(r.pg->submit(*r.h, kSzl0424a), mpi::RequestError::None);
  r.sim->run_until(kT5 + 100 * kMs + kSecond);
  EXPECT_EQ(r.replies().size(), before + 3);
}

TEST(HMpiLateAnswer, JobOfAConnectionReleasedDuringTheUpdateGetsNoAnswer) {
  PgRun r;
  ASSERT_NO_FATAL_FAILURE(r.connect());
  r.sim->run_until(kT1 + 50 * kMs);
  const std::size_t before = r.replies().size();
  ASSERT_EQ(r.pg->submit(*r.h, kSzl0424a), mpi::RequestError::None);
  r.sim->run_until(kT1 + 80 * kMs);
  ASSERT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 1u);
  // The PG releases its connection (80) before t5: the CPU's session ends with it.
  ASSERT_EQ(r.pg->close(*r.h), mpi::RequestError::None);
  r.sim->run_until(kT1 + 120 * kMs);
  EXPECT_EQ(r.pg->state(*r.h), mpi::State::Closed);
  r.sim->run_until(kT5 + 100 * kMs);
  EXPECT_EQ(r.replies().size(), before);
  EXPECT_EQ(r.cpu_data_message(kT1), r.rec.size());  // nothing sent from the CPU
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 0u);
}

TEST(HMpiLateAnswer, UpdateAbortedByTheStandbysFailureAnswersTheHeldJobInSolo) {
  // CPU 1 (the standby being updated) fails at 3.050 s: the update is aborted there and the
  // master goes on in Solo (000 L1680: the stored jobs are caught up on "after an abort ... back
  // in Solo mode"): the held job is answered from then, in RUN (08), not RUN-R.
  constexpr bus::Ticks kAbort = 3050 * kMs;
  PgRun r(kText + "fault { at: \"3050ms\" cpu_failure { rack: 1 } }\n");
  ASSERT_NO_FATAL_FAILURE(r.connect());
  r.sim->run_until(kT1 + 10 * kMs);
  const std::size_t before = r.replies().size();
  ASSERT_EQ(r.pg->submit(*r.h, kSzl0424a), mpi::RequestError::None);
  r.sim->run_until(kAbort - 1);
  EXPECT_EQ(r.sim->h_system(0).model().held_s7_jobs(), 1u);
  EXPECT_EQ(r.replies().size(), before);
  // The ring loses CPU 1's station with it; if it held the token, the PG claims it after its
  // TTO (6 x TSL = 2490 bits), polls the GAP to find CPU 2 and passes it the token: with one
  // more rotation and the answer frame, < 2490 + 1653 + 2 x 551 + 768 = 6013 bits = 32 ms.
  r.sim->run_until(kAbort + kSecond);
  const auto rs = r.replies();
  ASSERT_EQ(rs.size(), before + 1);
  EXPECT_GT(rs[before].at, kAbort);
  ASSERT_GT(rs[before].pdu.size(), 37u);
  EXPECT_EQ(rs[before].pdu[5], 0x14);
  EXPECT_EQ(rs[before].pdu[37], 0x08);  // RUN: Solo after the abort
  EXPECT_EQ(r.pg->state(*r.h), mpi::State::Connected);
}

TEST(HMpiLateAnswer, StandbyConnectionBrokenAtTheLinkUpIsReleasedAtTheNextJob) {
  // The PG is connected to CPU 1 (MPI 3, the standby in STOP) before the link-up; at 1 s the
  // link-up breaks the standby's connections (R8). The model's session answers nothing more;
  // at the PG's next job the CPU releases the MPI connection (80): the PG sees it closed by the
  // peer instead of waiting for an answer that never comes.
  PgRun r;
  ASSERT_NO_FATAL_FAILURE(r.connect(3));
  r.sim->run_until(1200 * kMs);
  ASSERT_EQ(r.pg->state(*r.h), mpi::State::Connected);  // nothing tells the PG before a job
  const std::size_t before = r.replies().size();
  ASSERT_EQ(r.pg->submit(*r.h, kSzl0424a), mpi::RequestError::None);
  r.sim->run_until(1200 * kMs + kSecond);
  EXPECT_EQ(r.replies().size(), before);
  EXPECT_EQ(r.pg->state(*r.h), mpi::State::Closed);
  std::vector<mpi_station::StationEvent> ends;
  for (const auto& e : r.events)
    if (e.kind == mpi_station::EventKind::Closed || e.kind == mpi_station::EventKind::Broken) ends.push_back(e);
  ASSERT_EQ(ends.size(), 1u);
  EXPECT_EQ(ends[0].kind, mpi_station::EventKind::Closed);
  EXPECT_EQ(ends[0].reason, mpi_station::EndReason::ByPeer);
  EXPECT_GT(ends[0].at, 1200 * kMs);
}

}  // namespace
}  // namespace pbvbus::tools
