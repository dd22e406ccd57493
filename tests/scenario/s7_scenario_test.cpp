// The scenario's S7 entries (scenario/proto/scenario.proto messages S7Cpu, MpiStation, S7Door,
// HMpi; scenario/include/pbvbus/scenario/s7_plan.hpp): MPI lines and their defaults, what the
// loader plans from valid entries, every check with its FILE:LINE:COLUMN message, and the S7
// item syntax.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

const std::string kFile = std::string(PBVBUS_SOURCE_DIR) + "/examples/s7.textproto";

// Lines 1..5; a test appends its entries from line 6 on. Columns are those of the field's name,
// counted by hand: `mpi_station { ` is 14 columns, so its first field starts at column 15.
const std::string kBase = R"(name: "s7"
duration: "1s"
line { name: "MPI" kind: MPI }
line { name: "DP" baud: "1.5M" }
dp_master { address: 2 line: "DP" }
)";

LoadResult load(const std::string& more) { return parse_scenario(kBase + more, kFile); }

std::vector<std::string> errors(const std::string& more) {
  std::vector<std::string> out;
  for (const auto& d : load(more).errors) {
    std::string s = d.str();
    if (s.rfind(kFile, 0) == 0) s = "s7.textproto" + s.substr(kFile.size());
    out.push_back(s);
  }
  return out;
}

TEST(S7Scenario, AnMpiLineRunsAt187_5kWithHsa31) {
  const auto r = load("");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const auto& mpi = r.plan->lines[0];
  EXPECT_TRUE(mpi.mpi);
  EXPECT_EQ(mpi.baud, bus::Baud::k187_5);
  EXPECT_EQ(mpi.params.hsa, 31);
  // docs/mpi.md "MPI bus parameters": TSL 415, min TSDR 20, max TSDR 400 (libnodave's adapter
  // record), TTR 20 000.
  EXPECT_EQ(mpi.params.tsl, 415u);
  EXPECT_EQ(mpi.params.min_tsdr, 20u);
  EXPECT_EQ(mpi.params.max_tsdr, 400u);
  EXPECT_EQ(mpi.params.ttr, 20000u);
  const auto& dp = r.plan->lines[1];
  EXPECT_FALSE(dp.mpi);
  EXPECT_EQ(dp.params.hsa, 126);
}

TEST(S7Scenario, AnMpiLineKeepsANamedBaudAndItsOwnHsa) {
  const auto r = parse_scenario(R"(name: "x" duration: "1s"
line { name: "M" kind: MPI baud: "1.5M" bus_params { hsa: 63 } }
)",
                                kFile);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  EXPECT_EQ(r.plan->lines[0].baud, bus::Baud::k1_5M);
  EXPECT_EQ(r.plan->lines[0].params.hsa, 63);
}

TEST(S7Scenario, DefaultAddressesArePg0Op1Cpu2AndTheDoorTakesTheLowestFree) {
  const auto r = load(R"(mpi_station { role: OP line: "MPI" }
s7_cpu { name: "C" mpi_dp { line: "MPI" } db { number: 1 size: 10 } }
mpi_station { line: "MPI" read { cpu: 2 item: "DB1.DBB0,10" } }
s7_door { name: "D" listen: "127.0.0.1:0" mpi_line: "MPI" route { rack: 0 slot: 2 mpi_address: 2 } }
)");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const ScenarioPlan& p = *r.plan;
  // Cable order = text order: OP, CPU, PG, then the door's station.
  const auto& st = p.lines[0].stations;
  ASSERT_EQ(st.size(), 4u);
  EXPECT_EQ(st[0].kind, StationKind::MpiStation);
  EXPECT_EQ(st[0].address, 1);
  EXPECT_EQ(st[1].kind, StationKind::S7CpuMpi);
  EXPECT_EQ(st[1].address, 2);
  EXPECT_EQ(st[2].kind, StationKind::MpiStation);
  EXPECT_EQ(st[2].address, 0);
  EXPECT_EQ(st[3].kind, StationKind::S7DoorMpi);
  EXPECT_EQ(st[3].address, 3);  // 0, 1 and 2 are taken
  ASSERT_EQ(p.s7.cpus.size(), 1u);
  EXPECT_EQ(p.s7.cpus[0].mpi_line, 0);
  EXPECT_EQ(p.s7.cpus[0].mpi_address, 2);
  EXPECT_EQ(p.s7.cpus[0].order_number, "6ES7 315-2AG10-0AB0");
  EXPECT_EQ(p.s7.cpus[0].max_connections, 12u);
  EXPECT_EQ(p.s7.cpus[0].input_bytes, 128u);
  EXPECT_EQ(p.s7.cpus[0].flag_bytes, 256u);
  ASSERT_EQ(p.s7.stations.size(), 2u);
  EXPECT_TRUE(p.s7.stations[0].op);
  EXPECT_FALSE(p.s7.stations[1].op);
  ASSERT_EQ(p.s7.stations[1].reads.size(), 1u);
  EXPECT_EQ(p.s7.stations[1].reads[0].item.str(), "DB1.DBB0,10");
  EXPECT_EQ(p.s7.stations[1].reads[0].period, 100 * bus::kTicksPerMs);
  ASSERT_EQ(p.s7.doors.size(), 1u);
  EXPECT_EQ(p.s7.doors[0].mpi_address, 3);
  EXPECT_EQ(p.s7.doors[0].idle_timeout, 60 * bus::kTicksPerSecond);
  ASSERT_EQ(p.s7.doors[0].routes.size(), 1u);
  EXPECT_EQ(p.s7.doors[0].routes[0].kind, S7RoutePlan::Kind::Mpi);
  EXPECT_EQ(p.s7.doors[0].routes[0].mpi_address, 2);
}

TEST(S7Scenario, ACpuWithBothDpInterfacesIsTheirDpMasters) {
  const auto r = load(R"(line { name: "DP2" }
dp_master { address: 1 line: "DP2" }
s7_cpu { name: "C" mpi_dp { mode: DP line: "DP" address: 2 } dp { mode: DP line: "DP2" address: 1 } }
)");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const auto& c = r.plan->s7.cpus[0];
  EXPECT_EQ(c.mpi_line, -1);
  ASSERT_TRUE(c.x1_dp && c.x2_dp);
  EXPECT_EQ(c.x1_dp->dp_master, 0);
  EXPECT_EQ(c.x2_dp->dp_master, 1);
  EXPECT_EQ(c.x2_dp->line, 2);
}

TEST(S7Scenario, NoDpOnAnMpiLineAndNoMpiStationOnADpLine) {
  // `dp_slave { address: 3 ` is 22 columns; `mpi_station { role: OP ` is 23.
  EXPECT_EQ(errors(R"(dp_slave { address: 3 line: "MPI" gsd: "gsd/PBVB0A01.gsd" }
mpi_station { role: OP line: "DP" }
)"),
            (std::vector<std::string>{
                "s7.textproto:6:23: dp_slave on MPI line \"MPI\": an MPI line carries no DP (put "
                "DP stations on a CPU's DP interface line)",
                "s7.textproto:7:24: mpi_station on line \"DP\": an MPI station needs a line of "
                "kind MPI"}));
}

TEST(S7Scenario, AnMpiAddressAboveHsaCannotJoinTheRing) {
  // `mpi_station { line: "MPI" ` is 26 columns.
  EXPECT_EQ(errors("mpi_station { line: \"MPI\" address: 40 }\n"),
            (std::vector<std::string>{
                "s7.textproto:6:27: MPI address 40 is above HSA 31 of line \"MPI\": no GAP poll "
                "would let the station into the token ring"}));
}

TEST(S7Scenario, TheCpuDefaultAddressCollidesWithAnExplicitOne) {
  // The PG at 2 comes first in the text; the CPU's default 2 collides (reported at its
  // mpi_dp, the `address` field being absent: `s7_cpu { name: "C" ` is 19 columns).
  EXPECT_EQ(errors(R"(mpi_station { line: "MPI" address: 2 }
s7_cpu { name: "C" mpi_dp { line: "MPI" } }
)"),
            (std::vector<std::string>{
                "s7.textproto:7:20: address 2 is already used on line \"MPI\" (at 6:27)"}));
}

TEST(S7Scenario, ReadsNameACpuOnTheLineAndAnItemInS7Syntax) {
  // `mpi_station { line: "MPI" ` 26 columns, `read { ` 7: `cpu` at 34; `cpu: 2 ` 7 more:
  // `item` at 41.
  EXPECT_EQ(errors(R"(s7_cpu { name: "C" mpi_dp { line: "MPI" } }
mpi_station { line: "MPI" read { cpu: 5 item: "DB1.DBB0" } }
mpi_station { line: "MPI" read { cpu: 2 item: "DB1.DBX0" } address: 1 }
mpi_station { line: "MPI" read { cpu: 2 item: "MW2" period: "0s" } address: 3 }
)"),
            (std::vector<std::string>{
                "s7.textproto:7:34: no S7 CPU at MPI address 5 on line \"MPI\"",
                "s7.textproto:8:41: bad item \"DB1.DBX0\": no width B, W or D (expected "
                "DBn.DBB/DBW/DBDx, MB/MW/MDx, IB/IW/IDx or QB/QW/QDx with an optional \",N\", e.g. "
                "\"DB1.DBW2\" or \"MB0,4\")",
                "s7.textproto:9:53: bad period \"0s\" (a duration > 0, e.g. \"100ms\")"}));
}

TEST(S7Scenario, CpuChecks) {
  // `s7_cpu { name: "C" ` is 19 columns; `dp { ` 5 more: `line` at 25, `line: "DP" ` 11:
  // address at 36 (X2 needs no `mode`: it is DP). Line 7: `s7_cpu { name: "E" mpi_dp { line:
  // "MPI" } db { number: 1 size: 4 } ` is 67 columns, then `db { ` 5: `number` at 73. Line 8:
  // `s7_cpu { name: "F" mpi_dp { mode: DP line: "DP" address: 2 } ` is 61 columns: flag_bytes
  // at 62; F takes dp_master 2, so G (line 9, `address` at 19 + 5 + 9 + 11 + 1 = 45) finds it
  // taken.
  EXPECT_EQ(
      errors(R"(s7_cpu { name: "C" dp { line: "DP" address: 7 } }
s7_cpu { name: "E" mpi_dp { line: "MPI" } db { number: 1 size: 4 } db { number: 1 size: 4 } }
s7_cpu { name: "F" mpi_dp { mode: DP line: "DP" address: 2 } flag_bytes: 20000 }
s7_cpu { name: "G" dp { mode: DP line: "DP" address: 2 } }
s7_cpu { name: "E" }
)"),
      (std::vector<std::string>{
          "s7.textproto:6:36: no dp_master 7 on line \"DP\" for this DP interface",
          "s7.textproto:7:73: DB 1 is defined twice",
          "s7.textproto:8:62: flag_bytes 20000 is over 16384",
          "s7.textproto:9:45: dp_master 2 on line \"DP\" is already the DP interface of s7_cpu \"F\"",
          "s7.textproto:10:10: s7_cpu \"E\" is defined twice",
          "s7.textproto:10:1: s7_cpu \"E\" has no interface (mpi_dp or dp)"}));
}

TEST(S7Scenario, DoorChecks) {
  // Line 6: `s7_door { name: "D" route { ` is 28 columns (rack at 29; `rack: 0 slot: 2 ` 16
  // more: cpu at 45). Line 7: `s7_door { name: "E" listen: "127.0.0.1:1" route { rack: 0 slot:
  // 2 ` is 10 + 10 + 22 + 8 + 16 = 66 columns: mpi_address at 67. Line 8: listen at 21 (a bad
  // listen says nothing more about ports), `listen: "x" route { ` 20 more: rack at 41. Line 9:
  // port 1 again (listen at 21), `h_system` at 42 + 8 + 16 + 1 = 67.
  EXPECT_EQ(
      errors(R"(s7_door { name: "D" route { rack: 0 slot: 2 cpu: "nope" } }
s7_door { name: "E" listen: "127.0.0.1:1" route { rack: 0 slot: 2 mpi_address: 2 } }
s7_door { name: "F" listen: "x" route { rack: 9 slot: 2 cpu: "C" } }
s7_door { name: "G" listen: "127.0.0.1:1" route { rack: 0 slot: 1 h_system: "H" } }
)"),
      (std::vector<std::string>{
          "s7.textproto:6:45: unknown s7_cpu \"nope\"",
          "s7.textproto:7:67: a route over MPI needs the door's `mpi_line` (a line of kind MPI)",
          "s7.textproto:8:21: bad listen \"x\" (expected HOST:PORT with a numeric IPv4 address or "
          "[IPv6] and a port 0..65535, e.g. \"127.0.0.1:10102\")",
          "s7.textproto:8:41: a route needs a rack 0..7",
          "s7.textproto:9:21: port 1 is used twice in the file",
          "s7.textproto:9:67: unknown h_system \"H\""}));
}

TEST(S7Scenario, ItemSyntax) {
  S7ItemPlan it;
  ASSERT_EQ(parse_s7_item("DB1.DBW2", it), "");
  EXPECT_EQ(it.area, S7ItemPlan::Area::Db);
  EXPECT_EQ(it.db, 1);
  EXPECT_EQ(it.byte, 2u);
  EXPECT_EQ(it.width, 2);
  EXPECT_EQ(it.count, 1);
  ASSERT_EQ(parse_s7_item("mb10,4", it), "");
  EXPECT_EQ(it.area, S7ItemPlan::Area::Flags);
  EXPECT_EQ(it.bytes(), 4u);
  EXPECT_EQ(it.str(), "MB10,4");
  ASSERT_EQ(parse_s7_item("EW0", it), "");  // German: E = input
  EXPECT_EQ(it.area, S7ItemPlan::Area::Inputs);
  EXPECT_EQ(it.str(), "IW0");
  ASSERT_EQ(parse_s7_item("AD4", it), "");  // A = output
  EXPECT_EQ(it.area, S7ItemPlan::Area::Outputs);
  EXPECT_EQ(it.width, 4);
  for (const char* bad : {"", "DB0.DBB0", "DB1.DBB", "DB1DBB0", "X0", "MB0,0", "MB0,", "MB0x",
                          "DB70000.DBB0", "MB70000"}) {
    EXPECT_NE(parse_s7_item(bad, it), "") << bad;
  }
}

}  // namespace
}  // namespace pbvbus::tools

namespace pbvbus::tools {
namespace {

TEST(S7Scenario, TheHCpusSitOnTheMpiLineWithTheirOwnAddresses) {
  const auto r = load(R"(h_system { name: "H" t_wa: "100ms" t_prog: "10ms" cpu { mpi { line: "MPI" } } }
mpi_station { line: "MPI" read { cpu: 3 item: "MW0" } }
s7_door { name: "D" listen: "127.0.0.1:0" route { rack: 0 slot: 3 h_system: "H" } }
)");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const ScenarioPlan& p = *r.plan;
  ASSERT_EQ(p.s7.h_mpi.size(), 1u);
  EXPECT_EQ(p.s7.h_mpi[0].h_system, 0);
  EXPECT_EQ(p.s7.h_mpi[0].address[0], 2);
  EXPECT_EQ(p.s7.h_mpi[0].address[1], 3);
  EXPECT_EQ(p.s7.h_mpi[0].max_connections, 44u);
  EXPECT_EQ(p.h_systems[0].runtime->pair.max_connections, 44);
  ASSERT_EQ(p.s7.h_memory.size(), 1u);
  EXPECT_EQ(p.s7.h_memory[0].memory.flags, 256u);
  const auto& st = p.lines[0].stations;
  ASSERT_EQ(st.size(), 3u);
  EXPECT_EQ(st[0].kind, StationKind::HCpuMpi);
  EXPECT_EQ(st[0].source, 0);  // h_system 0, rack 0
  EXPECT_EQ(st[1].source, 1);  // rack 1
  EXPECT_EQ(st[1].address, 3);
  EXPECT_EQ(p.s7.doors[0].routes[0].kind, S7RoutePlan::Kind::HSystem);
  EXPECT_EQ(p.s7.doors[0].routes[0].connection, -1);
}

TEST(S7Scenario, BothHCpusAtOneAddressIsAnError) {
  // `h_system { name: "H" t_wa: "100ms" t_prog: "10ms" cpu { mpi { line: "MPI" ` is 74 columns,
  // `address_cpu0: 5 ` 16 more: address_cpu1 at 91.
  EXPECT_EQ(
      errors("h_system { name: \"H\" t_wa: \"100ms\" t_prog: \"10ms\" cpu { mpi { line: \"MPI\" "
             "address_cpu0: 5 address_cpu1: 5 } } }\n"),
      (std::vector<std::string>{
          "s7.textproto:6:91: address 5 is already used on line \"MPI\" (at 6:75)",
          "s7.textproto:6:91: both CPUs have MPI address 5: CPU 1 differs from CPU 0 in its MPI "
          "address"}));
}

}  // namespace
}  // namespace pbvbus::tools
