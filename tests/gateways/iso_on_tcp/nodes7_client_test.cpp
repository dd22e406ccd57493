// nodes7 0.3.18 (npm, unmodified) through the door, against one CPU (rack 0, slot 2): connect by
// rack/slot, a multi-item read of DB bytes, INT, REAL, WORD, M, I, Q, a bit, a counter and a
// timer, writes of each kind checked in the CpuMemory and read back, and a read of a missing DB.
// `./pbvbus test` installs nodes7 into the build folder (BUILD/nodes7) before the suite runs;
// without it (npm unreachable) the test is skipped and says why.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>

#include "iso_test_support.hpp"

namespace pbvbus::iso_on_tcp::test {
namespace {

bool exists(const std::string& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0;
}

std::string nodes7_dir() {
  return std::string(PBVBUS_BINARY_DIR) + "/nodes7/node_modules";
}

/// Runs the client script against `port`; its `key=value` lines (value as JSON text).
std::map<std::string, std::string> run_client(std::uint16_t port, std::string& all) {
  const std::string cmd =
      "NODE_PATH='" + nodes7_dir() + "' node '" + std::string(PBVBUS_SOURCE_DIR) +
      "/tests/gateways/iso_on_tcp/data/nodes7_client.js' " + std::to_string(port) + " 2>&1";
  std::map<std::string, std::string> kv;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return kv;
  char line[4096];
  while (std::fgets(line, sizeof line, p)) {
    std::string l(line);
    all += l;
    if (!l.empty() && l.back() == '\n') l.pop_back();
    const auto eq = l.find('=');
    if (eq != std::string::npos) kv[l.substr(0, eq)] = l.substr(eq + 1);
  }
  ::pclose(p);
  return kv;
}

TEST(Nodes7, ReadsAndWritesASingleCpuThroughTheDoor) {
  if (std::system("node --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "node is not installed";
  if (!exists(nodes7_dir() + "/nodes7/nodeS7.js"))
    GTEST_SKIP() << "nodes7 0.3.18 is not in " << nodes7_dir()
                 << " (./pbvbus test installs it with npm; npm was unreachable?)";
  // The door's capture hook keeps the answers, to see the return code nodes7 was given.
  std::vector<Bytes> answers;
  IsoDoorOptions opt;
  opt.capture = [&answers](const PduRecord& r) {
    if (r.direction == PduDirection::ToClient) answers.emplace_back(r.pdu.begin(), r.pdu.end());
  };
  DoorFixture f(opt);
  f.on_io([&] {
    auto db = *f.memory.db(1);
    db[0] = 16;
    db[1] = 17;
    db[2] = 18;
    db[3] = 19;
    s7cpu::set_word(db, 4, 4627);         // INT 4627 = 0x1213
    s7cpu::set_dword(db, 8, 0x40490FDB);  // REAL 3.14159274 (IEEE 754 single of pi)
    s7cpu::set_word(db, 12, 0xCAFE);
    auto m = f.memory.area(s7cpu::Area::Flags);
    m[10] = 0x2A;
    m[11] = 0x02;  // M11.1 set
    f.memory.area(s7cpu::Area::Inputs)[0] = 0x81;
    f.memory.area(s7cpu::Area::Outputs)[0] = 0x42;
    f.memory.counters()[5] = 42;
    f.memory.counters()[40] = 43;
    f.memory.timers()[3] = 0x1234;
    f.memory.timers()[24] = 0x0111;
  });
  std::string all;
  const auto kv = run_client(f.port, all);
  SCOPED_TRACE(all);
  ASSERT_EQ(kv.count("done"), 1u);

  EXPECT_EQ(kv.at("multi_bad"), "false");
  EXPECT_EQ(kv.at("DB1,B0.4"), "[16,17,18,19]");
  EXPECT_EQ(kv.at("DB1,INT4"), "4627");
  EXPECT_EQ(kv.at("DB1,REAL8").substr(0, 7), "3.14159");
  EXPECT_EQ(kv.at("DB1,WORD12"), "51966");
  EXPECT_EQ(kv.at("MB10"), "42");
  EXPECT_EQ(kv.at("IB0"), "129");
  EXPECT_EQ(kv.at("QB0"), "66");
  EXPECT_EQ(kv.at("M11.1"), "true");
  // Counters and timers: nodes7 writes the address of "C5" as 5 * 8 = 40, as for the byte
  // areas, where snap7's client writes the cell number, which the CPU model follows
  // (docs/s7cpu.md "Addresses"). So nodes7's C5 is cell 40 and its T3 cell 24 (Int16BE).
  EXPECT_EQ(kv.at("C5"), "43");
  EXPECT_EQ(kv.at("T3"), "273");

  EXPECT_EQ(kv.at("write_bad"), "false");
  f.on_io([&] {
    const auto db = *f.memory.db(1);
    EXPECT_EQ(db[20], 0x5A);
    EXPECT_EQ(s7cpu::get_word(db, 22), 0xFB2E);        // -1234 as INT
    EXPECT_EQ(s7cpu::get_dword(db, 24), 0x40600000u);  // 3.5 as REAL
    EXPECT_EQ(s7cpu::get_word(db, 28), 0xBEEF);
    EXPECT_EQ(f.memory.area(s7cpu::Area::Flags)[20], 7);
    EXPECT_EQ(f.memory.area(s7cpu::Area::Outputs)[1], 0x81);
  });
  EXPECT_EQ(kv.at("back_bad"), "false");
  EXPECT_EQ(kv.at("back DB1,B20"), "90");
  EXPECT_EQ(kv.at("back DB1,INT22"), "-1234");
  EXPECT_EQ(kv.at("back DB1,REAL24"), "3.5");
  EXPECT_EQ(kv.at("back MB20"), "7");
  EXPECT_EQ(kv.at("back QB1"), "129");
  EXPECT_EQ(kv.at("back DB1,WORD28"), "48879");

  // A missing DB: the CPU answers the item with return code 0A (object does not exist). nodes7
  // reports the read as bad and, for a bad item, puts its quality text in place of the value:
  // "BAD 255" (nodes7 fills the quality of an item whose return code is not FF with 0xFF, "no
  // quality" in OPC terms; the S7 return code itself is not passed on).
  EXPECT_EQ(kv.at("missing_bad"), "true");
  EXPECT_EQ(kv.at("missing DB9,B0"), "\"BAD 255\"");
  f.on_io([&] {
    ASSERT_FALSE(answers.empty());
    const Bytes& last = answers.back();  // Read Var Ack-Data: 12 + 04 01 + the item
    ASSERT_GE(last.size(), 15u);
    EXPECT_EQ(last[12], 0x04);
    EXPECT_EQ(last[14], 0x0A);
  });
  EXPECT_EQ(f.stats().connects, 1u);
}

}  // namespace
}  // namespace pbvbus::iso_on_tcp::test
