// S7 communication in a running scenario (simulation/s7_nodes.hpp): a PG on an MPI line
// connects to a single CPU with the §H.3 trace's frames and reads a DB whose answer carries the
// bytes the CPU holds; the CPU's DP interface maps its slaves into I and Q; an OP reads
// periodically and its report says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "frame_recorder.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

const std::string kFile = std::string(PBVBUS_SOURCE_DIR) + "/examples/s7-run.textproto";

std::optional<ScenarioPlan> plan_of(const std::string& text) {
  auto r = parse_scenario(text, kFile);
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].str());
  return r.plan;
}

bool contains(const std::vector<std::uint8_t>& hay, const std::vector<std::uint8_t>& needle) {
  return std::search(hay.begin(), hay.end(), needle.begin(), needle.end()) != hay.end();
}

TEST(S7ScenarioRun, APgConnectsWithTheTraceFramesAndReadsWhatTheCpuHolds) {
  const auto plan = plan_of(R"(name: "pg" duration: "1s"
line { name: "MPI" kind: MPI }
s7_cpu { name: "C" mpi_dp { line: "MPI" } db { number: 1 size: 16 } }
mpi_station { line: "MPI" read { cpu: 2 item: "DB1.DBB0,10" period: "100ms" } }
)");
  ASSERT_TRUE(plan);
  Simulation sim(*plan);
  test::FrameRecorder rec;
  sim.line(0).add_tap(rec);
  auto db1 = sim.s7_cpu(0).memory().db(1);
  ASSERT_TRUE(db1);
  for (std::size_t i = 0; i < 10; ++i) (*db1)[i] = static_cast<std::uint8_t>(0xA0 + i);
  sim.start();
  sim.run_until(*sim.duration());

  const auto hex = rec.hex_all();
  // protocol-facts.md §H.3: PG 0 -> PLC 2 connect request, and the PLC's confirm from SAP 0x14.
  const std::string request = "68 11 11 68 82 80 6D 00 14 E0 04 00 80 00 02 00 02 01 00 01 00 ED 16";
  const std::string confirm = "68 11 11 68 80 82 6C 14 14 D0 04 00 80 00 02 00 02 01 00 01 00 F0 16";
  const auto req = std::find(hex.begin(), hex.end(), request);
  const auto conf = std::find(hex.begin(), hex.end(), confirm);
  ASSERT_NE(req, hex.end());
  ASSERT_NE(conf, hex.end());
  EXPECT_LT(req, conf);
  // The CPU's FDL answers the request with SC at once.
  EXPECT_EQ(*(req + 1), "E5");

  // The Read Var answer (§H.4: ack-data, 2 octets of parameters 04 01, 14 of data: FF 04,
  // 80 bits, the ten octets) inside a data message F1 nr from CPU 2 (SA 82) to PG 0 (DA 80).
  // Its PDU reference is 2: the PG's Setup Communication was 1.
  const std::vector<std::uint8_t> answer = {0x32, 0x03, 0x00, 0x00, 0x00, 0x02, 0x00, 0x02,
                                            0x00, 0x0E, 0x00, 0x00, 0x04, 0x01, 0xFF, 0x04,
                                            0x00, 0x50, 0xA0, 0xA1, 0xA2, 0xA3, 0xA4, 0xA5,
                                            0xA6, 0xA7, 0xA8, 0xA9};
  bool seen = false;
  for (const auto& f : rec.frames())
    if (f.bytes.size() > 12 && f.bytes[4] == 0x80 && f.bytes[5] == 0x82 && f.bytes[9] == 0xF1 &&
        contains(f.bytes, answer))
      seen = true;
  EXPECT_TRUE(seen) << "no Read Var answer with DB1's bytes from the CPU";

  const auto r = sim.s7_report();
  ASSERT_EQ(r.stations.size(), 1u);
  const auto& rd = r.stations[0].reads.at(0);
  // Once connected, one read per 100 ms in a 1 s run: the first within the first rotations.
  EXPECT_GE(rd.ok, 9u);
  EXPECT_LE(rd.ok, 10u);
  EXPECT_EQ(rd.errors, 0u);
  EXPECT_EQ(rd.last_value, std::vector<std::uint8_t>(answer.end() - 10, answer.end()));
  EXPECT_EQ(r.stations[0].breaks, 0u);
  ASSERT_EQ(r.cpus.size(), 1u);
  EXPECT_EQ(r.cpus[0].accepted, 1u);
  EXPECT_EQ(r.cpus[0].open, 1u);
}

TEST(S7ScenarioRun, TheCpusDpInterfaceMapsItsSlavesIntoIAndQ) {
  // Slaves 3 and 4 (PBVB0A01: one module 2 octets in, 2 out): slave 3 at IB0..1 / QB0..1,
  // slave 4 at IB2..3 / QB2..3 (ascending addresses, no addresses configured).
  const std::string text = R"(name: "dp" duration: "200ms"
line { name: "DP" }
dp_master { address: 2 line: "DP" }
dp_slave { address: 4 line: "DP" gsd: "gsd/PBVB0A01.gsd" master: 2 inputs: ZERO }
dp_slave { address: 3 line: "DP" gsd: "gsd/PBVB0A01.gsd" master: 2 inputs: COUNTER }
s7_cpu { name: "C" mpi_dp { mode: DP line: "DP" address: 2 } }
)";
  const auto plan = plan_of(text);
  ASSERT_TRUE(plan);
  Simulation sim(*plan);
  auto q = sim.s7_cpu(0).memory().area(s7cpu::Area::Outputs);
  q[0] = 0x12;
  q[1] = 0x34;
  q[2] = 0x56;
  q[3] = 0x78;
  sim.start();
  sim.run_until(*sim.duration());
  const auto rep = sim.report(1.0);
  const DpSlaveView* s3 = nullptr;
  const DpSlaveView* s4 = nullptr;
  for (const auto& v : rep.dp_slaves) (v.address == 3 ? s3 : s4) = &v;
  ASSERT_TRUE(s3 && s4);
  EXPECT_EQ(s3->outputs, (std::vector<std::uint8_t>{0x12, 0x34}));
  EXPECT_EQ(s4->outputs, (std::vector<std::uint8_t>{0x56, 0x78}));
  // I holds what the slaves sent in the last exchange: slave 3 counts, slave 4 sends zeros.
  const auto in = sim.s7_cpu(0).memory().area(s7cpu::Area::Inputs);
  EXPECT_NE(in[0] | in[1], 0);
  EXPECT_EQ(in[2] | in[3], 0);
  EXPECT_GT(sim.s7_cpu(0).dp_exchanges(), 100u);
  EXPECT_EQ(sim.s7_cpu(0).unmapped_bytes(), 0u);
}

TEST(S7ScenarioRun, TheCpusDpInterfaceRunsWithAConstantBusCycle) {
  // Equidistance on a standard CPU's DP interface (001 L13663-13666: standard S7-400 "yes";
  // docs/dp-equidistance.md): the dp_master entry that is the interface carries T_DP.
  const std::string text = R"(name: "dp" duration: "100ms"
line { name: "DP" }
dp_master { address: 2 line: "DP" equidistant_cycle: "2ms" }
dp_slave { address: 3 line: "DP" gsd: "gsd/PBVB0A01.gsd" master: 2 inputs: COUNTER }
s7_cpu { name: "C" mpi_dp { mode: DP line: "DP" address: 2 } }
)";
  const auto plan = plan_of(text);
  ASSERT_TRUE(plan);
  Simulation sim(*plan);
  auto q = sim.s7_cpu(0).memory().area(s7cpu::Area::Outputs);
  q[0] = 0x12;
  q[1] = 0x34;
  sim.start();
  sim.run_until(*sim.duration());
  const auto rep = sim.report(1.0);
  ASSERT_EQ(rep.dp_masters.size(), 1u);
  const auto& e = rep.dp_masters[0].equidistance;
  EXPECT_EQ(e.period, 2 * bus::kTicksPerMs);
  EXPECT_EQ(e.overruns, 0u);
  EXPECT_EQ(e.jitter, 0);
  EXPECT_GE(e.cycles, 49u);
  ASSERT_EQ(rep.dp_slaves.size(), 1u);
  EXPECT_EQ(rep.dp_slaves[0].outputs, (std::vector<std::uint8_t>{0x12, 0x34}));
}

TEST(S7ScenarioRun, ACpuInStopWritesZeroOutputs) {
  const auto plan = plan_of(R"(name: "stop" duration: "100ms"
line { name: "DP" }
dp_master { address: 2 line: "DP" }
dp_slave { address: 3 line: "DP" gsd: "gsd/PBVB0A01.gsd" master: 2 }
s7_cpu { name: "C" mode: STOP dp { line: "DP" address: 2 } }
)");
  ASSERT_TRUE(plan);
  Simulation sim(*plan);
  auto q = sim.s7_cpu(0).memory().area(s7cpu::Area::Outputs);
  q[0] = 0xFF;
  q[1] = 0xFF;
  sim.start();
  sim.run_until(*sim.duration());
  const auto rep = sim.report(1.0);
  ASSERT_EQ(rep.dp_slaves.size(), 1u);
  EXPECT_EQ(rep.dp_slaves[0].outputs, (std::vector<std::uint8_t>{0, 0}));
}

TEST(S7ScenarioRun, AReadOfAMissingDbIsCountedWithItsReturnCode) {
  const auto plan = plan_of(R"(name: "nodb" duration: "300ms"
line { name: "MPI" kind: MPI }
s7_cpu { name: "C" mpi_dp { line: "MPI" } }
mpi_station { role: OP line: "MPI" read { cpu: 2 item: "DB9.DBW0" } }
)");
  ASSERT_TRUE(plan);
  Simulation sim(*plan);
  sim.start();
  sim.run_until(*sim.duration());
  const auto r = sim.s7_report();
  const auto& rd = r.stations.at(0).reads.at(0);
  EXPECT_EQ(rd.ok, 0u);
  EXPECT_GE(rd.errors, 2u);
  EXPECT_EQ(rd.last_code, 0x0A);  // §H.4: object does not exist
}

}  // namespace
}  // namespace pbvbus::tools

namespace pbvbus::tools {
namespace {

TEST(S7ScenarioRun, TheCpusProgramWritesWhatClientsReadAndContinuesFromWhatTheyWrite) {
  // A counter (+1 every 100 ms) on QW 0; its value is MD 8 (docs/h-programs.md: 16 octets of
  // state per counter, the value at +8). The OP reads QW 0 and MD 8 over MPI.
  const auto plan = plan_of(R"(name: "prog" duration: "1s"
line { name: "MPI" kind: MPI }
s7_cpu { name: "C" mpi_dp { line: "MPI" }
  program { scan_time: "10ms" counter { output: 0 width: 2 period: "100ms" } } }
mpi_station { role: OP line: "MPI" read { cpu: 2 item: "QW0" period: "100ms" } read { cpu: 2 item: "MD8" period: "100ms" } }
)");
  ASSERT_TRUE(plan);
  Simulation sim(*plan);
  sim.start();
  sim.run_until(500 * bus::kTicksPerMs);
  auto& mem = sim.s7_cpu(0).memory();
  const auto q = mem.area(s7cpu::Area::Outputs);
  const auto m = mem.area(s7cpu::Area::Flags);
  // Periods start at 0: at 500 ms the counter has counted at 0, 100, ..., 400 (and 500 if
  // that scan has run): 5 or 6.
  const int before = q[0] * 256 + q[1];
  EXPECT_TRUE(before == 5 || before == 6) << before;
  EXPECT_EQ(m[8] * 16777216 + m[9] * 65536 + m[10] * 256 + m[11], before);
  // A client writes MD 8 = 1000 (as a Write Var would): the program continues from it.
  m[8] = 0;
  m[9] = 0;
  m[10] = 0x03;
  m[11] = 0xE8;
  sim.run_until(*sim.duration());
  const int after = q[0] * 256 + q[1];
  EXPECT_GE(after, 1004);
  EXPECT_LE(after, 1006);
  // The OP read both over MPI; its last values agree with each other.
  const auto r = sim.s7_report();
  const auto& qw = r.stations.at(0).reads.at(0);
  const auto& md = r.stations.at(0).reads.at(1);
  ASSERT_EQ(qw.last_value.size(), 2u);
  ASSERT_EQ(md.last_value.size(), 4u);
  EXPECT_GE(qw.last_value[0] * 256 + qw.last_value[1], 1000);
  EXPECT_GE(md.last_value[2] * 256 + md.last_value[3], 1000);
  EXPECT_GT(sim.s7_cpu(0).scans(), 90u);
}

TEST(S7ScenarioRun, AProgramThatDoesNotFitTheImagesIsRefused) {
  // `s7_cpu { name: "C" mpi_dp { line: "MPI" } ` is 9 + 10 + 9 + 12 + 2 = 42 columns: `program`
  // at 43.
  const auto r = parse_scenario(R"(name: "p" duration: "1s"
line { name: "MPI" kind: MPI }
s7_cpu { name: "C" mpi_dp { line: "MPI" } program { copy { from_input: 0 to_output: 200 length: 2 } } }
)", kFile);
  ASSERT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].line, 3);
  EXPECT_EQ(r.errors[0].column, 43);
  EXPECT_NE(r.errors[0].message.find("program: "), std::string::npos) << r.errors[0].message;
}


// The DP system functions of a plain CPU's program (docs/h-dp-sfc.md) on its DP master (X1 in DP
// mode, address 2): SFC 11 at 50 ms sends SYNC (MODE 0x20) to group 1 (GROUP 0x01); SFC 12
// deactivates slave 4 at 100 ms (MODE 2), asks at 150 ms (MODE 0: W#16#0001 deactivated) and
// activates it at 200 ms (MODE 1); SFC 14/15 move slave 3's inputs (IB 0..1) to slave 4's outputs
// (QB 2..3) through MB 30..31; a 4-octet RECORD for the 2-octet module: W#16#80B1.
TEST(S7ScenarioRun, TheProgramsDpSfcsActOnTheCpusDpMaster) {
  const auto plan = plan_of(R"(name: "sfc" duration: "300ms"
line { name: "DP" }
dp_master { address: 2 line: "DP" }
dp_slave { address: 3 line: "DP" gsd: "gsd/PBVB0A01.gsd" master: 2 inputs: COUNTER }
dp_slave { address: 4 line: "DP" gsd: "gsd/PBVB0A01.gsd" master: 2 inputs: ZERO }
s7_cpu { name: "C" mpi_dp { mode: DP line: "DP" address: 2 } program {
  dpsyc_fr { at: "50ms" line: "DP" group: 1 mode: 32 ret_val: 20 }
  d_act_dp { at: "100ms" line: "DP" station: 4 mode: 2 ret_val: 22 }
  d_act_dp { at: "150ms" line: "DP" station: 4 mode: 0 ret_val: 26 }
  d_act_dp { at: "200ms" line: "DP" station: 4 mode: 1 ret_val: 24 }
  dprd_dat { laddr: 0 record: 30 length: 2 ret_val: 28 }
  dpwr_dat { laddr: 2 record: 30 length: 2 ret_val: 32 }
  dprd_dat { laddr: 0 record: 40 length: 4 ret_val: 34 }
} }
)");
  ASSERT_TRUE(plan);
  Simulation sim(*plan);
  test::FrameRecorder rec;
  sim.line(0).add_tap(rec);
  sim.start();
  sim.run_until(*sim.duration());
  constexpr bus::Ticks kMs = bus::kTicksPerMs;

  // Global_Control (protocol-facts.md §D.6): SD2, LE = 7 (DA SA FC + DSAP SSAP + 2 octets),
  // DA 127 | 0x80 = FF (SAPs follow), SA 2 | 0x80 = 82, FC 46 (SDN high, FCB/FCV 0), DSAP 3A (58),
  // SSAP 3E (62), Control_Command 20 (SYNC; Operate: no Clear_Data), Group_Select 01;
  // FCS = FF+82+46+3A+3E+20+01 = 0x260 -> 60.
  const std::vector<std::uint8_t> sync = {0x68, 0x07, 0x07, 0x68, 0xFF, 0x82, 0x46,
                                          0x3A, 0x3E, 0x20, 0x01, 0x60, 0x16};
  std::vector<bus::Ticks> sync_at;
  for (const auto& f : rec.frames())
    if (f.bytes == sync) sync_at.push_back(f.start);
  ASSERT_EQ(sync_at.size(), 1u);
  EXPECT_GE(sync_at[0], 50 * kMs);
  EXPECT_LT(sync_at[0], 60 * kMs);  // the OB 1 at 50 ms, then the master's next pass

  // Requests of master 2 to slave 4 (SD2, DA 04 or 84, SA 02 or 82), by time; Set_Prm has
  // DSAP 3D (61).
  auto requests = [&](bus::Ticks from, bus::Ticks to, bool set_prm_only) {
    int n = 0;
    for (const auto& f : rec.frames())
      if (f.bytes.size() > 8 && f.bytes[0] == 0x68 && (f.bytes[4] & 0x7F) == 4 && (f.bytes[5] & 0x7F) == 2 &&
          f.start >= from && f.start < to && (!set_prm_only || ((f.bytes[4] & 0x80) != 0 && f.bytes[7] == 0x3D)))
        ++n;
    return n;
  };
  EXPECT_GT(requests(50 * kMs, 100 * kMs, false), 10);
  EXPECT_EQ(requests(110 * kMs, 200 * kMs, false), 0);  // deactivated: not polled
  EXPECT_GT(requests(210 * kMs, 300 * kMs, false), 10);  // polled again ...
  EXPECT_EQ(requests(200 * kMs, 300 * kMs, true), 1);    // ... after a new Set_Prm

  const auto m = sim.s7_cpu(0).memory().area(s7cpu::Area::Flags);
  auto mw = [&](std::size_t at) { return static_cast<std::uint16_t>((m[at] << 8) | m[at + 1]); };
  EXPECT_EQ(mw(20), 0x0000);  // SFC 11 done
  EXPECT_EQ(mw(22), 0x0000);  // SFC 12 deactivated
  EXPECT_EQ(mw(26), 0x0001);  // SFC 12 MODE 0: deactivated
  EXPECT_EQ(mw(24), 0x0000);  // SFC 12 activated
  EXPECT_EQ(mw(28), 0x0000);
  EXPECT_EQ(mw(32), 0x0000);
  EXPECT_EQ(mw(34), 0x80B1);
  EXPECT_NE(mw(30), 0);  // slave 3 counts
  const auto& calls = sim.s7_cpu(0).dp_sfc_calls();
  ASSERT_EQ(calls.size(), 4u);
  EXPECT_EQ(calls[0].sfc, 11);
  EXPECT_EQ(calls[0].time, 50 * kMs);  // OB 1 every 10 ms from 0
}

TEST(S7ScenarioRun, Sfc11And12NameOneOfTheCpusDpInterfaces) {
  auto r = parse_scenario(R"(name: "sfc" duration: "300ms"
line { name: "DP" }
dp_master { address: 2 line: "DP" }
s7_cpu { name: "C" mpi_dp { mode: DP line: "DP" address: 2 } program {
  d_act_dp { line: "X" station: 4 mode: 2 }
} }
)", kFile);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].str().find(":5:14: SFC 12: line \"X\" is not a DP interface of s7_cpu \"C\""),
            std::string::npos)
      << r.errors[0].str();
}

}  // namespace
}  // namespace pbvbus::tools
