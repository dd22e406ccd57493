// PassiveStation on a real Line + Scheduler: the bytes it puts on the wire and when
// (protocol-facts.md §B, §C.2, §C.6, Appendix 1). Requests are written by hand as golden bytes and
// sent by a scripted master; replies are checked against golden bytes written by hand too.

#include "pbvbus/fdl/passive_station.hpp"

#include <gtest/gtest.h>

#include <functional>

#include "fdl_station_helpers.hpp"
#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"

namespace pbvbus::fdl {
namespace {

using pbvbus::test::bytes_from_hex;
using pbvbus::test::FrameRecorder;
using test::ScriptDevice;

struct Seen {
  std::uint8_t sa = 0, da = 0;
  RequestFn fn{};
  std::optional<std::uint8_t> dsap, ssap;
  std::vector<std::uint8_t> data;
  bus::Ticks now = 0;
};

class TestUser final : public ResponderUser {
 public:
  void on_request(const Indication& ind, Reply& reply) override {
    seen.push_back({ind.sa, ind.da, ind.fn, ind.dsap, ind.ssap, {ind.data.begin(), ind.data.end()}, ind.now});
    if (handler) handler(ind, reply);
  }
  bus::Ticks next_deadline() const override { return deadline; }
  void on_time(bus::Ticks now) override {
    times.push_back(now);
    deadline = bus::kNever;
  }
  std::function<void(const Indication&, Reply&)> handler;
  std::vector<Seen> seen;
  std::vector<bus::Ticks> times;
  bus::Ticks deadline = bus::kNever;
};

class PassiveStationTest : public ::testing::Test {
 protected:
  explicit PassiveStationTest(std::uint8_t addr = 3, std::uint32_t tsdr = 0)
      : slave(addr, params, user, tsdr) {}

  void SetUp() override {
    line.add_tap(rec);
    line.attach(master, "master 1");
    line.attach(slave, "slave");
    line.attach(other, "other");
    line.start();
  }
  bus::Ticks bits(std::int64_t n) const { return bus::bits_to_ticks(n, bus::Baud::k1_5M); }
  /// Sends `hex` from the scripted master at bit time `at_bits` and runs the bus for a while.
  void send(std::int64_t at_bits, std::string_view hex, ScriptDevice* from = nullptr) {
    (from ? *from : master).send(bits(at_bits), bytes_from_hex(hex));
  }
  void run_to(std::int64_t at_bits) { sched.run_until(bits(at_bits)); }
  std::vector<FrameRecorder::Frame> slave_frames() const {
    std::vector<FrameRecorder::Frame> out;
    for (const auto& f : rec.frames())
      if (f.sender == 1) out.push_back(f);
    return out;
  }

  BusParams params = BusParams::defaults(bus::Baud::k1_5M);
  bus::Scheduler sched;
  bus::Line line{sched, "dp", bus::Baud::k1_5M};
  FrameRecorder rec;
  ScriptDevice master, other;
  TestUser user;
  PassiveStation slave;
};

TEST_F(PassiveStationTest, AnswersFdlStatusAfterMinTsdr) {
  // Appendix 1: Request FDL Status 1 -> 3, reply from a slave.
  send(1000, "10 03 01 49 4D 16");
  run_to(3000);
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.hex(1), "10 01 03 00 04 16");
  // Request: 6 octets * 11 bits = 66 bits, ends at bit 1066; reply starts min TSDR (11) later.
  EXPECT_EQ(rec.end_bits(0), 1066);
  EXPECT_EQ(rec.start_bits(1), 1066 + 11);
  EXPECT_EQ(rec.end_bits(1), 1077 + 66);
  EXPECT_TRUE(user.seen.empty()) << "FDL Status is answered by the FDL, not the user";
  EXPECT_EQ(slave.stats().fdl_status, 1u);
}

TEST_F(PassiveStationTest, IgnoresFramesForOthersAndTokens) {
  send(1000, "10 0A 01 49 54 16");  // FDL Status to station 10
  send(2000, "DC 03 01");           // a token to station 3: not for a passive station
  run_to(4000);
  EXPECT_EQ(rec.size(), 2u);
  EXPECT_TRUE(slave_frames().empty());
}

TEST_F(PassiveStationTest, SapsMirroredAndSd3Reply) {
  PassiveStation diag_slave(10, params, user);
  // Replace the slave by one at address 10 on a fresh line.
  bus::Scheduler s2;
  bus::Line l2{s2, "dp2", bus::Baud::k1_5M};
  FrameRecorder r2;
  ScriptDevice m2;
  l2.add_tap(r2);
  l2.attach(m2);
  l2.attach(diag_slave);
  l2.start();
  user.handler = [](const Indication& ind, Reply& r) {
    if (ind.dsap == 60) {
      const std::uint8_t diag[] = {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34};
      r.respond(ResponseStatus::DL, diag);
    }
  };
  // Appendix 1: Slave_Diag request 1 -> 10 (first frame), reply as SD3.
  m2.send(bus::bits_to_ticks(500, bus::Baud::k1_5M), bytes_from_hex("68 05 05 68 8A 81 6D 3C 3E F2 16"));
  s2.run_until(bus::bits_to_ticks(2000, bus::Baud::k1_5M));
  ASSERT_EQ(r2.size(), 2u);
  EXPECT_EQ(r2.hex(1), "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
  EXPECT_EQ(r2.start_bits(1), 500 + 11 * 11 + 11);
  ASSERT_EQ(user.seen.size(), 1u);
  EXPECT_EQ(user.seen[0].sa, 1);
  EXPECT_EQ(user.seen[0].dsap, 60);
  EXPECT_EQ(user.seen[0].ssap, 62);
  EXPECT_EQ(user.seen[0].fn, RequestFn::SrdHigh);
  EXPECT_TRUE(user.seen[0].data.empty());
}

TEST_F(PassiveStationTest, DataExchangeWithoutSaps) {
  PassiveStation dx_slave(10, params, user);
  bus::Scheduler s2;
  bus::Line l2{s2, "dp2", bus::Baud::k1_5M};
  FrameRecorder r2;
  ScriptDevice m2;
  l2.add_tap(r2);
  l2.attach(m2);
  l2.attach(dx_slave);
  l2.start();
  user.handler = [](const Indication&, Reply& r) {
    const std::uint8_t in[] = {0x3C};
    r.respond(ResponseStatus::DL, in);
  };
  // Appendix 1: Data_Exchange with 2 output bytes; reply with 1 input byte.
  m2.send(bus::bits_to_ticks(500, bus::Baud::k1_5M), bytes_from_hex("68 05 05 68 0A 01 5D AA 55 67 16"));
  s2.run_until(bus::bits_to_ticks(2000, bus::Baud::k1_5M));
  ASSERT_EQ(r2.size(), 2u);
  EXPECT_EQ(r2.hex(1), "68 04 04 68 01 0A 08 3C 4F 16");
  ASSERT_EQ(user.seen.size(), 1u);
  EXPECT_FALSE(user.seen[0].dsap.has_value());
  EXPECT_EQ(user.seen[0].data, (std::vector<std::uint8_t>{0xAA, 0x55}));
}

TEST_F(PassiveStationTest, FcbRepeatAnsweredFromStoredReply) {
  PassiveStation diag_slave(10, params, user);
  bus::Scheduler s2;
  bus::Line l2{s2, "dp2", bus::Baud::k1_5M};
  FrameRecorder r2;
  ScriptDevice m2;
  l2.add_tap(r2);
  l2.attach(m2);
  l2.attach(diag_slave);
  l2.start();
  int calls = 0;
  user.handler = [&](const Indication&, Reply& r) {
    ++calls;
    if (calls == 1) {
      const std::uint8_t d[] = {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34};
      r.respond(ResponseStatus::DL, d);
    } else {
      const std::uint8_t d[] = {0x00, 0x0C, 0x00, 0x01, 0x12, 0x34};
      r.respond(ResponseStatus::DL, d);
    }
  };
  auto at = [](std::int64_t b) { return bus::bits_to_ticks(b, bus::Baud::k1_5M); };
  // First frame (FCV=0, FCB=1), then FCV=1/FCB=0 (new), then FCV=1/FCB=0 again (repeat).
  m2.send(at(500), bytes_from_hex("68 05 05 68 8A 81 6D 3C 3E F2 16"));
  m2.send(at(1500), bytes_from_hex("68 05 05 68 8A 81 5D 3C 3E E2 16"));
  m2.send(at(2500), bytes_from_hex("68 05 05 68 8A 81 5D 3C 3E E2 16"));
  // A new FCB (FCV=1, FCB=1) executes again.
  m2.send(at(3500), bytes_from_hex("68 05 05 68 8A 81 7D 3C 3E 02 16"));
  s2.run_until(at(5000));
  ASSERT_EQ(r2.size(), 8u);
  EXPECT_EQ(r2.hex(1), "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
  EXPECT_EQ(r2.hex(3), "A2 81 8A 08 3E 3C 00 0C 00 01 12 34 E0 16");
  EXPECT_EQ(r2.hex(5), "A2 81 8A 08 3E 3C 00 0C 00 01 12 34 E0 16") << "repeat: stored reply";
  EXPECT_EQ(r2.start_bits(5), 2500 + 121 + 11) << "a repeat is answered with the same TSDR";
  EXPECT_EQ(r2.hex(7), "A2 81 8A 08 3E 3C 00 0C 00 01 12 34 E0 16");
  EXPECT_EQ(calls, 3) << "the repeat must not reach the user";
  EXPECT_EQ(diag_slave.stats().repeats, 1u);
}

TEST_F(PassiveStationTest, FcbIsKeptPerSourceAddress) {
  // Station 2 sends the same FC as station 1's last frame: not a repeat for station 2.
  int calls = 0;
  user.handler = [&](const Indication&, Reply& r) {
    ++calls;
    r.short_ack();
  };
  // SDA high first frame 1 -> 3: 68 05 05 68 03 01 65 AB CD E1 16 (FCS 03+01+65+AB+CD = 0x1E1).
  send(500, "68 05 05 68 03 01 65 AB CD E1 16");
  // The same from station 2 (SA 02, FCS one more): executed again, not a repeat.
  send(1500, "68 05 05 68 03 02 65 AB CD E2 16", &other);
  run_to(3000);
  ASSERT_EQ(rec.size(), 4u);
  EXPECT_EQ(rec.hex(1), "E5");
  EXPECT_EQ(rec.hex(3), "E5");
  EXPECT_EQ(rec.start_bits(1), 500 + 121 + 11);
  EXPECT_EQ(calls, 2);
}

TEST_F(PassiveStationTest, StatusOnlyReplyIsSd1) {
  // SRD to SAP 40 (not activated): the default reply RS goes out as SD1 without SAPs.
  // Request FCS: 83+81+6D+28+3E = 0x1D7 -> D7. Reply 10 01 03 03 07 16 (FCS 01+03+03).
  send(500, "68 05 05 68 83 81 6D 28 3E D7 16");
  run_to(2000);
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.hex(1), "10 01 03 03 07 16");
  ASSERT_EQ(user.seen.size(), 1u);
  EXPECT_EQ(user.seen[0].dsap, 40);
}

TEST_F(PassiveStationTest, SdnAndBroadcastNeverAnswered) {
  user.handler = [](const Indication&, Reply& r) { r.short_ack(); };  // would answer if allowed
  // Appendix 1: Global_Control Clear, broadcast SDN high.
  send(500, "68 07 07 68 FF 81 46 3A 3E 02 00 40 16");
  // SDN low addressed to station 3: 68 05 05 68 03 01 44 AB CD C0 16 (03+01+44+AB+CD = 0x1C0).
  send(1500, "68 05 05 68 03 01 44 AB CD C0 16");
  run_to(3000);
  EXPECT_EQ(rec.size(), 2u);
  EXPECT_TRUE(slave_frames().empty());
  ASSERT_EQ(user.seen.size(), 2u);
  EXPECT_EQ(user.seen[0].da, 127);
  EXPECT_EQ(user.seen[0].fn, RequestFn::SdnHigh);
  EXPECT_EQ(user.seen[0].dsap, 58);
  EXPECT_EQ(user.seen[1].da, 3);
}

TEST_F(PassiveStationTest, TsynViolationIgnored) {
  // A token to someone else ends at bit 1033; a request 32 bits later lacks TSYN: ignored.
  send(1000, "DC 05 01");
  send(1033 + 32, "10 03 01 49 4D 16");
  // The same after exactly 33 idle bits is answered.
  send(2000, "DC 05 01");
  send(2033 + 33, "10 03 01 49 4D 16");
  run_to(4000);
  ASSERT_EQ(slave_frames().size(), 1u);
  EXPECT_EQ(slave_frames()[0].bytes, bytes_from_hex("10 01 03 00 04 16"));
  EXPECT_EQ(slave.stats().dropped_tsyn, 1u);
  ASSERT_EQ(rec.size(), 5u);
  EXPECT_EQ(rec.start_bits(4), 2066 + 66 + 11);
}

TEST_F(PassiveStationTest, CorruptFramesIgnored) {
  send(500, "10 03 01 49 4E 16");  // bad FCS
  send(1500, "10 03 01 49 4D 17");  // bad end delimiter
  // Two masters at once: both frames collide and arrive damaged.
  send(2500, "10 03 01 49 4D 16");
  send(2500, "10 03 02 49 4E 16", &other);
  run_to(4000);
  EXPECT_TRUE(slave_frames().empty());
  EXPECT_GE(slave.stats().dropped_errors, 2u);
  EXPECT_TRUE(user.seen.empty());
}

TEST_F(PassiveStationTest, UserDeadlineDrivesOnTime) {
  user.deadline = bits(5000);
  slave.on_power_on(sched.now());  // re-reads the deadline (as after a power cycle)
  run_to(6000);
  ASSERT_EQ(user.times.size(), 1u);
  EXPECT_EQ(user.times[0], bits(5000));
}

class PassiveDelayTest : public PassiveStationTest {
 protected:
  PassiveDelayTest() : PassiveStationTest(3, 500) {}
};

TEST_F(PassiveDelayTest, OwnTsdrClampedToMaxTsdr) {
  EXPECT_EQ(slave.response_delay(), 150u);  // max TSDR at 1.5M
  send(500, "10 03 01 49 4D 16");
  run_to(2000);
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.start_bits(1), 566 + 150);
}

TEST(PassiveStationSetAddress, RunTimeChangeMovesTheFilterAndForgetsTheFcbs) {
  // set_address() at run time (the Flying Redundancy address swap): the line's cached receive
  // filter follows at once, and the FCB stored for master 1 under the old address does not make
  // the first request to the new address a repeat.
  const BusParams params = BusParams::defaults(bus::Baud::k1_5M);
  TestUser user;
  user.handler = [](const Indication&, Reply& r) { r.short_ack(); };
  bus::Scheduler sched;
  bus::Line line{sched, "dp", bus::Baud::k1_5M};
  FrameRecorder rec;
  ScriptDevice m;
  PassiveStation slave(10, params, user);
  line.add_tap(rec);
  line.attach(m);
  line.attach(slave);
  line.start();
  auto at = [](std::int64_t b) { return bus::bits_to_ticks(b, bus::Baud::k1_5M); };
  m.send(at(500), bytes_from_hex("10 0A 01 7D 88 16"));  // SRD_HIGH FCV=1 FCB=1 to 10
  sched.run_until(at(1000));
  slave.set_address(74);
  EXPECT_EQ(slave.address(), 74);
  m.send(at(1500), bytes_from_hex("10 0A 01 49 54 16"));  // FDL Status to 10: nobody
  m.send(at(2500), bytes_from_hex("10 4A 01 49 94 16"));  // FDL Status to 74
  m.send(at(3500), bytes_from_hex("10 4A 01 7D C8 16"));  // FCB=1 again, now to 74: executed
  m.send(at(4500), bytes_from_hex("10 4A 01 7D C8 16"));  // same FCB: a repeat
  sched.run_until(at(6000));
  ASSERT_EQ(rec.size(), 9u);
  EXPECT_EQ(rec.hex(1), "E5");
  EXPECT_EQ(rec.hex(2), "10 0A 01 49 54 16");
  EXPECT_EQ(rec.hex(4), "10 01 4A 00 4B 16");
  EXPECT_EQ(rec.hex(6), "E5");
  EXPECT_EQ(rec.hex(8), "E5");
  ASSERT_EQ(user.seen.size(), 2u);
  EXPECT_EQ(user.seen[0].da, 10);
  EXPECT_EQ(user.seen[1].da, 74);
  EXPECT_EQ(slave.stats().repeats, 1u);
}

TEST(PassiveStationSetPrm, NewMinTsdrAndAddressApplyAfterTheReply) {
  const BusParams params = BusParams::defaults(bus::Baud::k1_5M);
  TestUser user;
  user.handler = [](const Indication& ind, Reply& r) {
    r.short_ack();
    if (ind.dsap == 61) r.new_min_tsdr = 40;  // Set_Prm octet 4 (0x0B = 11 in the frame; test value)
    if (ind.dsap == 55) r.new_address = 5;    // Set_Slave_Add
  };
  bus::Scheduler sched;
  bus::Line line{sched, "dp", bus::Baud::k1_5M};
  FrameRecorder rec;
  ScriptDevice m;
  PassiveStation slave(126, params, user);
  line.add_tap(rec);
  line.attach(m);
  line.attach(slave);
  line.start();
  auto at = [](std::int64_t b) { return bus::bits_to_ticks(b, bus::Baud::k1_5M); };
  // Appendix 1: Set_Slave_Add 126 -> 5. Reply E5 from 126; afterwards the station is 5.
  m.send(at(500), bytes_from_hex("68 09 09 68 FE 81 6D 37 3E 05 12 34 00 AC 16"));
  // FDL Status to 5: 10 05 01 49 4F 16 -> 10 01 05 00 06 16.
  m.send(at(1500), bytes_from_hex("10 05 01 49 4F 16"));
  // Appendix 1 Set_Prm (sent to station 10 there; here DA 5|EXT: 85 instead of 8A, FCS 0xD0 - 5).
  m.send(at(2500), bytes_from_hex("68 0C 0C 68 85 81 5D 3D 3E 88 0A 0A 0B 12 34 00 CB 16"));
  m.send(at(3500), bytes_from_hex("10 05 01 49 4F 16"));
  sched.run_until(at(5000));
  ASSERT_EQ(rec.size(), 8u);
  EXPECT_EQ(rec.hex(1), "E5");
  EXPECT_EQ(rec.hex(3), "10 01 05 00 06 16");
  EXPECT_EQ(rec.hex(5), "E5");
  EXPECT_EQ(rec.start_bits(5), 2500 + 18 * 11 + 11) << "the Set_Prm reply still uses the old min TSDR";
  EXPECT_EQ(rec.hex(7), "10 01 05 00 06 16");
  EXPECT_EQ(rec.start_bits(7), 3500 + 66 + 40);
  EXPECT_EQ(slave.address(), 5);
  // Power cycle: min TSDR back to the bus parameter, the address stays.
  line.set_power(1, false);
  line.set_power(1, true);
  EXPECT_EQ(slave.min_tsdr(), 11u);
  EXPECT_EQ(slave.address(), 5);
}

}  // namespace
}  // namespace pbvbus::fdl
