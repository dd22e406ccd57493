// S7 communication in the H CPUs (h_s7_memory.hpp, h_s7_session.hpp, docs/h-system.md
// "S7 communication"): the fixture of h_system_fixture.hpp (power_on_both at 12 ms, Solo at
// 1.012 s with rack 0 master, rack 1 in LINK-UP from 1.012 s, UPDATE at 3.012 s, t4 = t5 =
// 3.157 s Redundant; OB 1 every 10 ms). Every S7 PDU below is worked out by hand
// (protocol-facts.md §H.4; docs/s7.md byte layouts); values the program produces are compared
// with the CPU's own image.
#include <gmock/gmock.h>

#include "h_system_fixture.hpp"
#include "hex.hpp"
#include "pbvbus/s7cpu/s7_server.hpp"

namespace pbvbus::devices {
namespace {

using ::testing::HasSubstr;

Bytes hex(std::string_view s) {
  std::string clean;
  for (const char c : s)
    if (c != '|') clean.push_back(c);
  return test::bytes_from_hex(clean);
}

// Setup Communication (tools-and-formats.md §3.4): AmQ 1/1, PDU 480 asked, 240 answered.
const Bytes kSetup = hex("32 01 00 00 00 00 00 08 00 00 | F0 00 00 01 00 01 01 E0");
const Bytes kSetupAnswer = hex("32 03 00 00 00 00 00 08 00 00 00 00 | F0 00 00 01 00 01 00 F0");
// Write Var DB1.DBW0 = 12 34 (pdu-ref 3): item 12 0A 10 | 02 WORD... as BYTE x 2 | DB 1 |
// area 84 | address 0; data FF-less item 00 04 00 10 12 34 (16 bits).
const Bytes kWriteDbw0 = hex(
    "32 01 00 00 00 03 00 0E 00 06 | 05 01 12 0A 10 02 00 02 00 01 84 00 00 00"
    "| 00 04 00 10 12 34");
const Bytes kWriteOk = hex("32 03 00 00 00 03 00 02 00 01 00 00 | 05 01 | FF");
// Read Var DB1.DBW0 (pdu-ref 4) and its answer carrying 12 34.
const Bytes kReadDbw0 = hex("32 01 00 00 00 04 00 0E 00 00 | 04 01 12 0A 10 02 00 02 00 01 84 00 00 00");
const Bytes kReadDbw0Is1234 = hex("32 03 00 00 00 04 00 02 00 06 00 00 | 04 01 | FF 04 00 10 12 34");
// Read Var, 2 items (pdu-ref 2): MD 8 (BYTE x 4, area 83, bit address 64 = 0x40) and QW 0
// (BYTE x 2, area 82, address 0). Parameters 2 + 2 x 12 = 26 = 0x1A.
const Bytes kReadMd8Qw0 = hex(
    "32 01 00 00 00 02 00 1A 00 00 | 04 02 | 12 0A 10 02 00 04 00 00 83 00 00 40"
    "| 12 0A 10 02 00 02 00 00 82 00 00 00");
// Write Var MD 8 = 00 00 10 00 (pdu-ref 5).
const Bytes kWriteMd8 = hex(
    "32 01 00 00 00 05 00 0E 00 08 | 05 01 12 0A 10 02 00 04 00 00 83 00 00 40"
    "| 00 04 00 20 00 00 10 00");

/// Read SZL `id`/`index` (pdu-ref 0x0014, sequence 0; docs/s7.md "SZL").
Bytes szl_request(std::uint16_t id, std::uint16_t index) {
  Bytes b = hex("32 07 00 00 00 14 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04");
  for (const std::uint16_t v : {id, index}) {
    b.push_back(static_cast<std::uint8_t>(v >> 8));
    b.push_back(static_cast<std::uint8_t>(v));
  }
  return b;
}
/// The answer's head (Userdata header with data length `dlen`, 12 octets of parameters with
/// the error code).
Bytes szl_head(std::uint16_t dlen, std::uint16_t error) {
  Bytes b = hex("32 07 00 00 00 14 00 0C");
  b.push_back(static_cast<std::uint8_t>(dlen >> 8));
  b.push_back(static_cast<std::uint8_t>(dlen));
  const Bytes p = hex("00 01 12 08 12 84 01 00 00 00");
  b.insert(b.end(), p.begin(), p.end());
  b.push_back(static_cast<std::uint8_t>(error >> 8));
  b.push_back(static_cast<std::uint8_t>(error));
  return b;
}
Bytes cat(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}
/// The state octet of a 0424 answer (records start after 10 + 12 + 4 + 8 octets).
std::uint8_t state_of(const Bytes& a) { return a.size() > 37 ? a[34 + 3] : 0xFF; }

ProgramSpec counter_spec() {
  ProgramSpec p;
  p.scan_time = kScan;
  p.counters.push_back({0, 2, 10 * kMs, 1, 0, 0, 0});  // QW 0 = the low word of its value
  return p;
}

struct S7Sys : HSys {
  S7Sys() {
    HS7MemoryConfig m;
    m.flags = 64;
    m.dbs = {{1, 16}, {2, 4}};
    h->set_program(counter_spec());
    h->set_s7_memory(m);  // after the spec: the execution is rebuilt with the memory area
    EXPECT_EQ(h->add_cp({0, 0, CpKind::Cp443_1}), "");
    EXPECT_EQ(h->add_cp({1, 0, CpKind::Cp443_1}), "");
    EXPECT_EQ(h->add_connection({"s0", ConnectionKind::Standard, 0, 0}), "");
    EXPECT_EQ(h->add_connection({"s1", ConnectionKind::Standard, 1, 0}), "");
    EXPECT_EQ(h->add_connection({"ft", ConnectionKind::FaultTolerant, 0, 0}), "");
  }
  Bytes ask(HS7Session& s, const Bytes& pdu) { return s.handle(pdu); }
  bool setup(HS7Session& s) { return s.handle(kSetup) == kSetupAnswer; }
  std::uint16_t db1w0(int rack) { return *s7cpu::get_word(*h->s7_cpu_memory(rack).db(1), 0); }
  std::size_t ob72() const {
    std::size_t n = 0;
    for (const auto& e : h->events())
      if (e.ob == 72) ++n;
    return n;
  }
};

TEST(HS7Memory, LayoutFlagsGrowToTheProgramThenDbs) {
  HS7MemoryConfig c;
  c.flags = 8;
  c.dbs = {{7, 10}, {3, 2}};
  const HS7Layout l = layout(c, 16);  // one counter: 16 octets of state
  EXPECT_EQ(l.flags, 16u);
  ASSERT_EQ(l.dbs.size(), 2u);
  EXPECT_EQ(l.dbs[0].number, 7);
  EXPECT_EQ(l.dbs[0].offset, 16u);
  EXPECT_EQ(l.dbs[1].offset, 26u);
  EXPECT_EQ(l.total, 28u);
  c.dbs.push_back({7, 1});
  c.dbs.push_back({0, 1});
  const auto e = validate(c);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_THAT(e[0], HasSubstr("DB 7 is configured twice"));
  EXPECT_THAT(e[1], HasSubstr("DB 0"));
  HSys s;
  EXPECT_THROW(s.h->set_s7_memory(c), std::invalid_argument);
}

// What the program writes is what a client reads: the counter's value is MD 8 (its state is
// MB 0..15: next period u64, value u32, flags) and its low word is QW 0, in one Read Var
// answered between two scans.
TEST(HS7, ProgramStateIsReadableAsFlagsAndOutputs) {
  S7Sys s;
  s.bring_up();  // Redundant, 3.457 s
  HS7Session c = s.h->open_s7_adhoc(0);
  ASSERT_TRUE(c.alive()) << c.close_text();
  ASSERT_TRUE(s.setup(c));
  const Bytes a = s.ask(c, kReadMd8Qw0);
  // Ack-Data, data 8 + 6 = 14 = 0x0E: FF 04 00 20 <MD 8> | FF 04 00 10 <QW 0>.
  ASSERT_EQ(a.size(), 12u + 2u + 14u);
  EXPECT_EQ(Bytes(a.begin(), a.begin() + 14), hex("32 03 00 00 00 02 00 02 00 0E 00 00 | 04 02"));
  EXPECT_EQ(Bytes(a.begin() + 14, a.begin() + 18), hex("FF 04 00 20"));
  EXPECT_EQ(Bytes(a.begin() + 22, a.begin() + 26), hex("FF 04 00 10"));
  const auto mem = s.h->execution()->image(0).memory();
  EXPECT_EQ(Bytes(a.begin() + 18, a.begin() + 22), Bytes(mem.begin() + 8, mem.begin() + 12));
  EXPECT_EQ(Bytes(a.begin() + 20, a.begin() + 22), Bytes(a.begin() + 26, a.begin() + 28));
  EXPECT_NE(a[21], 0);  // the counter ran
}

// A Write Var on the master in Redundant mode reaches both CPUs: the comparison (PIQ + memory)
// stays quiet, and the program continues from the written value at its next scan.
TEST(HS7, WriteReachesBothCpusInRedundantAndTheProgramSeesIt) {
  S7Sys s;
  s.bring_up();
  HS7Session c = s.h->open_s7_adhoc(0);
  ASSERT_TRUE(s.setup(c));
  EXPECT_EQ(s.ask(c, kWriteDbw0), kWriteOk);
  EXPECT_EQ(s.db1w0(0), 0x1234);
  EXPECT_EQ(s.db1w0(1), 0x1234);
  EXPECT_EQ(s.ask(c, kWriteMd8), hex("32 03 00 00 00 05 00 02 00 01 00 00 | 05 01 | FF"));
  s.run_until(s.sched.now() + 10 * kMs);  // the next OB 1 on both CPUs
  EXPECT_EQ(s.ob72(), 0u);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  // 0x1000 + 1 per scan: QW 0 = 10 01 on both CPUs.
  for (int r = 0; r < 2; ++r) {
    const auto piq = s.h->execution()->image(r).piq();
    EXPECT_EQ(piq[0], 0x10) << r;
    EXPECT_EQ(piq[1], 0x01) << r;
  }
  EXPECT_EQ(s.h->execution()->image(0), s.h->execution()->image(1));
  s.run_until(s.sched.now() + 500 * kMs);
  EXPECT_EQ(s.ob72(), 0u);
}

// R8: the standby's connections break at link-up; none are accepted from the start of the
// link-up to the end of the update; a write on the master during the link-up reaches the
// standby through the update's copy (no comparison error afterwards).
TEST(HS7, LinkUpBreaksTheStandbysSessionsAndRefusesNewOnes) {
  S7Sys s;
  s.at(kT0);
  s.h->power_on_both();
  s.at(500 * kMs);  // rack 0 master in STARTUP, rack 1 waiting in STOP
  HS7Session m = s.h->open_s7_adhoc(0);
  HS7Session sb = s.h->open_s7_adhoc(1);
  ASSERT_TRUE(m.alive()) << m.close_text();
  ASSERT_TRUE(sb.alive()) << sb.close_text();
  EXPECT_EQ(s.h->pair().connections(0), 1);
  EXPECT_EQ(s.h->pair().connections(1), 1);
  ASSERT_TRUE(s.setup(sb));
  EXPECT_EQ(state_of(s.ask(sb, szl_request(0x0424, 0))), 0x04);  // STOP
  s.at(2000 * kMs);  // rack 1 in LINK-UP
  ASSERT_EQ(s.h->pair().state(1), CpuState::LinkUp);
  EXPECT_FALSE(sb.alive());
  EXPECT_EQ(sb.close_reason(), S7CloseReason::LinkUp);
  EXPECT_TRUE(s.ask(sb, kReadDbw0).empty());  // answers nothing more
  EXPECT_TRUE(m.alive());
  for (int r = 0; r < 2; ++r) {
    HS7Session n = s.h->open_s7_adhoc(r);
    EXPECT_EQ(n.close_reason(), S7CloseReason::Refused);
    EXPECT_THAT(n.close_text(), HasSubstr("R8"));
  }
  EXPECT_EQ(s.h->open_s7_connection("s0").close_reason(), S7CloseReason::Refused);  // not yet
  ASSERT_TRUE(s.setup(m));
  EXPECT_EQ(state_of(s.ask(m, szl_request(0x0424, 0))), 0x08);  // RUN (Solo)
  EXPECT_EQ(s.ask(m, kWriteDbw0), kWriteOk);
  EXPECT_EQ(s.db1w0(0), 0x1234);
  EXPECT_EQ(s.db1w0(1), 0x0000);  // the standby gets it from the update
  s.at(3100 * kMs);               // UPDATE: SFC 51 lists are not available (D406)
  ASSERT_EQ(s.h->pair().state(1), CpuState::Update);
  EXPECT_EQ(s.ask(m, szl_request(0x0071, 0)), cat(szl_head(0x0004, 0xD406), hex("0A 00 00 00")));
  EXPECT_EQ(s.h->open_s7_adhoc(0).close_reason(), S7CloseReason::Refused);
  s.at(kRedundant + 300 * kMs);
  EXPECT_EQ(s.db1w0(1), 0x1234);
  EXPECT_EQ(s.ob72(), 0u);
  EXPECT_EQ(state_of(s.ask(m, szl_request(0x0424, 0))), 0x09);  // RUN-R
  HS7Session again = s.h->open_s7_adhoc(1);
  EXPECT_TRUE(again.alive());
  EXPECT_EQ(s.h->pair().connections(1), 1);
  again.close();
  EXPECT_EQ(again.close_reason(), S7CloseReason::Closed);
  EXPECT_EQ(s.h->pair().connections(1), 0);  // the resource is back
}

// The same DB value whichever CPU is master: written on rack 0 in Redundant, read over the
// fault-tolerant connection before and after the master fails; the standard connection of the
// failed CPU and its ad-hoc session end; the standard connection of rack 1 goes on.
TEST(HS7, SameValueWhicheverCpuIsMasterFaultTolerantSurvives) {
  S7Sys s;
  s.bring_up();
  HS7Session ft = s.h->open_s7_connection("ft");
  HS7Session s0 = s.h->open_s7_connection("s0");
  HS7Session s1 = s.h->open_s7_connection("s1");
  HS7Session a0 = s.h->open_s7_adhoc(0);
  for (HS7Session* x : {&ft, &s0, &s1, &a0}) ASSERT_TRUE(x->alive()) << x->close_text();
  EXPECT_EQ(s.h->open_s7_connection("ft").close_reason(), S7CloseReason::Refused);  // in use
  EXPECT_EQ(ft.route(), S7Route::FaultTolerant);
  EXPECT_EQ(ft.answering_rack(), 0);
  EXPECT_EQ(s1.answering_rack(), 1);
  for (HS7Session* x : {&ft, &s0, &s1, &a0}) ASSERT_TRUE(s.setup(*x));
  EXPECT_EQ(s.ask(a0, kWriteDbw0), kWriteOk);
  EXPECT_EQ(s.ask(ft, kReadDbw0), kReadDbw0Is1234);
  EXPECT_EQ(s.ask(s1, kReadDbw0), kReadDbw0Is1234);  // the standby's own memory
  s.at(4000 * kMs);
  s.h->power_off(0);  // the master fails: rack 1 master in Solo
  ASSERT_EQ(s.h->pair().master(), 1);
  EXPECT_EQ(s0.close_reason(), S7CloseReason::ConnectionLost);
  EXPECT_EQ(a0.close_reason(), S7CloseReason::CpuLost);
  EXPECT_TRUE(s.ask(s0, kReadDbw0).empty());
  ASSERT_TRUE(ft.alive()) << ft.close_text();
  EXPECT_EQ(ft.answering_rack(), 1);
  EXPECT_EQ(s.ask(ft, kReadDbw0), kReadDbw0Is1234);
  EXPECT_EQ(s.ask(s1, kReadDbw0), kReadDbw0Is1234);
  EXPECT_EQ(state_of(s.ask(ft, szl_request(0x0424, 0))), 0x08);  // Solo RUN
  s.at(4500 * kMs);
  HS7Session a1 = s.h->open_s7_adhoc(1);
  ASSERT_TRUE(s.setup(a1));
  EXPECT_EQ(s.ask(a1, kReadDbw0), kReadDbw0Is1234);
}

// F4: a CP failure ends the standard connection over it; the fault-tolerant one switches path
// and keeps answering the same data.
TEST(HS7, CpFailureFaultTolerantSwitchesPathStandardIsLost) {
  S7Sys s;
  s.bring_up();
  HS7Session ft = s.h->open_s7_connection("ft");
  HS7Session s0 = s.h->open_s7_connection("s0");
  ASSERT_TRUE(s.setup(ft));
  ASSERT_TRUE(s.setup(s0));
  EXPECT_EQ(s.ask(s0, kWriteDbw0), kWriteOk);
  ASSERT_TRUE(s.h->cp_failure(0, 0));
  EXPECT_EQ(s0.close_reason(), S7CloseReason::ConnectionLost);
  EXPECT_THAT(s0.close_text(), HasSubstr("'s0'"));
  ASSERT_TRUE(ft.alive());
  const Connection& c = s.h->comms().connections()[static_cast<std::size_t>(s.h->comms().find("ft"))];
  EXPECT_EQ(c.paths[static_cast<std::size_t>(c.active)].rack, 1);
  EXPECT_EQ(s.ask(ft, kReadDbw0), kReadDbw0Is1234);
  // A re-established connection is a new one: the old session stays closed.
  ASSERT_TRUE(s.h->repair_cp(0, 0));
  EXPECT_EQ(s.h->comms().connections()[0].state, ConnectionState::Established);
  EXPECT_FALSE(s0.alive());
  HS7Session s0b = s.h->open_s7_connection("s0");
  EXPECT_TRUE(s0b.alive()) << s0b.close_text();
}

// Seed S7: a routing connection through the master to a device behind switched station 5 is
// cleared at the switchover; the device's own S7 endpoint answers while it lasts.
TEST(HS7, RoutingConnectionIsDroppedAtTheSwitchover) {
  S7Sys s;
  s.bring_up();
  s7cpu::CpuMemory dev_mem;
  dev_mem.create_db(1, 2);
  ASSERT_TRUE(s7cpu::set_word(*dev_mem.db(1), 0, 0x1234));
  s7cpu::CpuInfo dev_info;
  s7cpu::S7Server dev(dev_mem, dev_info);
  int asked = 0;
  S7Endpoint ep = [&](std::span<const std::uint8_t> pdu) {
    ++asked;
    return dev.handle(pdu).value;
  };
  EXPECT_EQ(s.h->open_s7_routing(0, kOneA, ep).close_reason(), S7CloseReason::Refused);
  EXPECT_EQ(s.h->open_s7_routing(3, kFast, ep).close_reason(), S7CloseReason::Refused);
  HS7Session r = s.h->open_s7_routing(0, kFast, ep);
  ASSERT_TRUE(r.alive()) << r.close_text();
  EXPECT_EQ(r.answering_rack(), -1);
  ASSERT_TRUE(s.setup(r));
  EXPECT_EQ(s.ask(r, kReadDbw0), kReadDbw0Is1234);
  EXPECT_EQ(asked, 2);
  s.at(4000 * kMs);
  s.h->power_off(0);  // master switchover: the IM switches to line B
  EXPECT_EQ(r.close_reason(), S7CloseReason::Switchover);
  EXPECT_TRUE(s.ask(r, kReadDbw0).empty());
  EXPECT_EQ(asked, 2);
  // At the switchover itself the IM has no active channel yet: refused.
  EXPECT_THAT(s.h->open_s7_routing(0, kFast, ep).close_text(), HasSubstr("no active channel"));
  // The user re-establishes it once the IM's new active channel runs.
  s.at(4500 * kMs);
  HS7Session again = s.h->open_s7_routing(0, kFast, ep);
  ASSERT_TRUE(again.alive()) << again.close_text();
  ASSERT_TRUE(s.setup(again));
  EXPECT_EQ(s.ask(again, kReadDbw0), kReadDbw0Is1234);
}

// The H lists over Read SZL, answered by the session's CPU: xy71 byte for byte in Redundant
// (h_ssl.hpp layout), and the S7 error codes for SFC 51's RET_VAL 8082 / 8083.
TEST(HS7, HListsOverReadSzl) {
  S7Sys s;
  s.bring_up();
  HS7Session c = s.h->open_s7_adhoc(0);
  ASSERT_TRUE(s.setup(c));
  // data 4 + 8 + 16 = 28 = 0x1C; list length 24 = 0x18. Record: redinf 0012 | mwstat1 10
  // (rack 0 master) | mwstat2 01 (synchronisation possible; racks' bits 0 in Redundant) |
  // hsfcinfo 0000 | samfehl 0000 | bz_cpu_1 0009 | bz_cpu_2 0009 (RUN-R) | 0000 | cpu_valid 03
  // | 00.
  EXPECT_EQ(s.ask(c, szl_request(0x0071, 0)),
            cat(szl_head(0x001C, 0),
                hex("FF 09 00 18 | 00 71 00 00 | 00 10 00 01"
                    "| 00 12 10 01 00 00 00 00 00 09 00 09 00 00 03 00")));
  EXPECT_EQ(s.ask(c, szl_request(0x0071, 1)), cat(szl_head(0x0004, 0xD402), hex("0A 00 00 00")));
  EXPECT_EQ(s.ask(c, szl_request(0x0C75, 0x0163)),
            cat(szl_head(0x0004, 0xD402), hex("0A 00 00 00")));  // station 99: none
  EXPECT_EQ(s.ask(c, szl_request(0x0F74, 0)), cat(szl_head(0x0004, 0xD401), hex("0A 00 00 00")));
  // 0011: the profile's order number.
  const Bytes m = s.ask(c, szl_request(0x0011, 0));
  ASSERT_EQ(m.size(), 34u + 28u);
  EXPECT_EQ(Bytes(m.begin() + 36, m.begin() + 56),
            Bytes({'6', 'E', 'S', '7', ' ', '4', '1', '7', '-', '5', 'H', 'T', '0', '6', '-', '0',
                   'A', 'B', '0', ' '}));
}

// Without a ProgramSpec (the fixture's hook program): M and the DBs live in the model's own
// storage per CPU, I and Q are the model's one PII/PIQ; a write during the link-up reaches the
// standby through the update's copy at t4, a write in Redundant reaches both at once; counters
// and timers are copied at t4 too.
TEST(HS7, HookProgramMemoryFollowsTheSameRules) {
  HSys s;
  HS7MemoryConfig m;
  m.dbs = {{1, 4}};
  s.h->set_s7_memory(m);
  s.at(kT0);
  s.h->power_on_both();
  s.at(500 * kMs);
  HS7Session c = s.h->open_s7_adhoc(0);  // before the link-up (R8)
  ASSERT_TRUE(c.handle(kSetup) == kSetupAnswer);
  s.at(2000 * kMs);
  EXPECT_EQ(c.handle(kWriteDbw0), kWriteOk);
  // Write Var C 3 = 00 2A (area 1C, transport 1C, count 1, address 3; data transport 09),
  // pdu-ref 6.
  EXPECT_EQ(c.handle(hex("32 01 00 00 00 06 00 0E 00 06 | 05 01 12 0A 10 1C 00 01 00 00 1C 00 00 03"
                         "| 00 09 00 02 00 2A")),
            hex("32 03 00 00 00 06 00 02 00 01 00 00 | 05 01 | FF"));
  EXPECT_EQ(*s7cpu::get_word(*s.h->s7_cpu_memory(1).db(1), 0), 0x0000);
  EXPECT_EQ(s.h->s7_cpu_memory(1).counters()[3], 0);
  s.at(kRedundant + 100 * kMs);
  EXPECT_EQ(*s7cpu::get_word(*s.h->s7_cpu_memory(1).db(1), 0), 0x1234);
  EXPECT_EQ(s.h->s7_cpu_memory(1).counters()[3], 0x2A);
  // In Redundant: DB1.DBW2 (pdu-ref 3 again) reaches both at once.
  Bytes w = kWriteDbw0;
  w[23] = 0x10;  // the address's low octet: 2 x 8 = 16 = 0x10
  EXPECT_EQ(c.handle(w), kWriteOk);
  EXPECT_EQ(*s7cpu::get_word(*s.h->s7_cpu_memory(1).db(1), 2), 0x1234);
  // QW 0 is the hook's counter in the model's PIQ, the same for both CPUs.
  HS7Session d = s.h->open_s7_adhoc(1);
  ASSERT_TRUE(d.handle(kSetup) == kSetupAnswer);
  const Bytes q = d.handle(hex("32 01 00 00 00 09 00 0E 00 00 | 04 01 12 0A 10 02 00 02 00 00 82 00 00 00"));
  ASSERT_EQ(q.size(), 20u);
  EXPECT_EQ(Bytes(q.begin() + 18, q.end()), Bytes(s.h->piq().begin(), s.h->piq().begin() + 2));
}

// The MPI connection resources (HCpuPairParams::max_connections): a clear refusal beyond them,
// and a closed session gives its resource back.
TEST(HS7, ConnectionResourcesAreCounted) {
  HCpuPairParams p;
  p.max_connections = 2;
  HSys s(p);
  s.bring_up();
  HS7Session a = s.h->open_s7_adhoc(0);
  HS7Session b = s.h->open_s7_adhoc(0);
  ASSERT_TRUE(a.alive() && b.alive());
  HS7Session c = s.h->open_s7_adhoc(0);
  EXPECT_EQ(c.close_reason(), S7CloseReason::Refused);
  EXPECT_EQ(c.close_text(), "all 2 connection resources of CPU 0 are in use");
  EXPECT_TRUE(s.h->open_s7_adhoc(1).alive());  // per CPU
  a.close();
  EXPECT_TRUE(s.h->open_s7_adhoc(0).alive());
}

// Garbage ends a session (ProtocolError); a destroyed handle gives the resource back.
TEST(HS7, ProtocolErrorAndRelease) {
  S7Sys s;
  s.bring_up();
  {
    HS7Session c = s.h->open_s7_adhoc(0);
    EXPECT_EQ(s.h->pair().connections(0), 1);
    EXPECT_TRUE(s.ask(c, hex("33 01 00 00")).empty());
    EXPECT_EQ(c.close_reason(), S7CloseReason::ProtocolError);
    EXPECT_EQ(s.h->pair().connections(0), 0);
  }
  {
    HS7Session c = s.h->open_s7_adhoc(0);
    HS7Session d = std::move(c);
    EXPECT_TRUE(d.alive());
    EXPECT_EQ(s.h->s7_sessions_alive(), 1u);
  }
  EXPECT_EQ(s.h->s7_sessions_alive(), 0u);
  EXPECT_EQ(s.h->pair().connections(0), 0);
}

}  // namespace
}  // namespace pbvbus::devices
