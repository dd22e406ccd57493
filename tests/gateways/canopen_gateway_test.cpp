// The CANopen gateway against a FakeSource, driven in virtual time by a bus::Scheduler; a
// recording port on the hub plays the CAN tool. Golden frames are in candump notation and were
// worked out by hand from CiA 301's predefined connection set (COB-ID = function code + node):
// TPDO1..4 0x180/0x280/0x380/0x480, RPDO1..4 0x200/0x300/0x400/0x500, EMCY 0x080, heartbeat
// 0x700, SDO 0x600 (request) / 0x580 (response). Times are virtual: "11ms" = 11 × kTicksPerMs.
#include "pbvbus/gateways/canopen_gateway.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fake_source.hpp"
#include "hex.hpp"

namespace pbvbus::gateways {
namespace {

constexpr bus::Ticks ms = bus::kTicksPerMs;
constexpr bus::Ticks half_ms = bus::kTicksPerMs / 2;

SourceModule mod(const char* name, std::size_t in, std::size_t out) {
  SourceModule m;
  m.name = name;
  m.in_len = in;
  m.out_len = out;
  return m;
}

CanFrame frame(std::string_view candump) {
  const auto hash = candump.find('#');
  CanFrame f;
  f.id = static_cast<std::uint32_t>(std::stoul(std::string(candump.substr(0, hash)), nullptr, 16));
  f.extended = hash > 3;
  const auto data = pbvbus::test::bytes_from_hex(candump.substr(hash + 1));
  f.dlc = static_cast<std::uint8_t>(data.size());
  std::copy(data.begin(), data.end(), f.data.begin());
  return f;
}

class CanopenGatewayTest : public ::testing::Test {
 protected:
  bus::Scheduler sched;
  test::FakeSource src;
  CanHub hub;
  std::vector<std::pair<bus::Ticks, std::string>> rec;
  CanHub::PortId tool = hub.add_port("tool", [this](const CanFrame& f, bus::Ticks now) {
    rec.emplace_back(now, to_string(f));
  });
  std::unique_ptr<CanopenGateway> gw;

  /// Slave 5 (ident 0x0A03): "5DI" 5 input octets; "2DO" output octets 0..1; "4AO" 2..5.
  void add_slave5() {
    src.add_slave(5, 0x0A03, {mod("5DI", 5, 0), mod("2DO", 0, 2), mod("4AO", 0, 4)});
    src.data(5).inputs = {0x01, 0x02, 0x03, 0x04, 0x05};
  }
  void make(CanopenOptions o = {}) { gw = std::make_unique<CanopenGateway>(sched, src, hub, o); }
  void start() {
    gw->start(sched.now());
    sched.run_until(sched.now());
  }
  void at(bus::Ticks t, std::function<void()> fn) { sched.schedule(t, std::move(fn)); }
  void run_to(bus::Ticks t) { sched.run_until(t); }
  void send(std::string_view candump) { hub.send(tool, frame(candump), sched.now()); }
  void send(const CanFrame& f) { hub.send(tool, f, sched.now()); }
  /// "<time> <frame>" of every recorded frame whose candump text starts with one of `prefixes`.
  std::vector<std::string> log(std::initializer_list<std::string_view> prefixes = {""}) const {
    std::vector<std::string> out;
    for (const auto& [t, s] : rec) {
      bool match = false;
      for (auto p : prefixes) match = match || s.starts_with(p);
      if (!match) continue;
      const std::string when =
          t % ms == 0 ? std::to_string(t / ms) + "ms" : std::to_string(t) + "ticks";
      out.push_back(when + " " + s);
    }
    return out;
  }
  using Log = std::vector<std::string>;
};

// --- TPDOs -------------------------------------------------------------------------------------

TEST_F(CanopenGatewayTest, BootUpAndTpdoAtStart) {
  // Node 5: boot-up 0x700 + 5 = 705 with state 0x00, then TPDO1 0x180 + 5 = 185 carrying the 5
  // input octets (DLC 5). The first change-detection tick is the start instant itself.
  add_slave5();
  make();
  start();
  EXPECT_EQ(log(), (Log{"0ms 705#00", "0ms 185#0102030405"}));
  run_to(99 * ms);
  EXPECT_EQ(log().size(), 2u);
  EXPECT_EQ(gw->stats().tpdo_sent, 1u);
  EXPECT_EQ(gw->stats().bootup_sent, 1u);
}

TEST_F(CanopenGatewayTest, ChangedInputsGoOutAtTheNextChangeDetectionTick) {
  add_slave5();
  make();
  start();
  // A change at 10.5 ms is seen at the 1 ms tick after it: 11 ms.
  at(10 * ms + half_ms, [&] { src.data(5).inputs[2] = 0x33; });
  run_to(20 * ms);
  EXPECT_EQ(log({"185"}), (Log{"0ms 185#0102030405", "11ms 185#0102330405"}));
}

TEST_F(CanopenGatewayTest, ChangeDetectionPeriodIsAnOption) {
  add_slave5();
  CanopenOptions o;
  o.change_period = 5 * ms;
  make(o);
  start();
  at(10 * ms + half_ms, [&] { src.data(5).inputs[0] = 0xFF; });  // ticks at 0, 5, 10, 15 ms
  run_to(20 * ms);
  EXPECT_EQ(log({"185"}), (Log{"0ms 185#0102030405", "15ms 185#FF02030405"}));
}

TEST_F(CanopenGatewayTest, CyclicTpdosEveryCycleTimeAndOneFrameWhenBothAreDue) {
  add_slave5();
  make();
  start();
  run_to(350 * ms);
  // k × 100 ms from the start, unchanged data.
  EXPECT_EQ(log({"185"}), (Log{"0ms 185#0102030405", "100ms 185#0102030405",
                               "200ms 185#0102030405", "300ms 185#0102030405"}));
  // A change seen at 400 ms, which is also a cycle instant: one frame, the new data.
  at(399 * ms + half_ms, [&] { src.data(5).inputs[4] = 0x55; });
  run_to(450 * ms);
  EXPECT_EQ(log({"185"}).back(), "400ms 185#0102030455");
  EXPECT_EQ(log({"185"}).size(), 5u);
}

TEST_F(CanopenGatewayTest, CycleTimeZeroMeansOnChangeOnly) {
  add_slave5();
  CanopenOptions o;
  o.tpdo_cycle = 0;
  make(o);
  start();
  run_to(1000 * ms);
  EXPECT_EQ(log({"185"}), (Log{"0ms 185#0102030405"}));
}

TEST_F(CanopenGatewayTest, FourTpdosOnlyTheChangedOneAndUnmappedInputsWarned) {
  // Slave 7: 40 input octets 00..27 → TPDO1..4 carry 00..1F, 20..27 are not mapped.
  // Slave 8: 12 input octets → TPDO1 8 octets, TPDO2 DLC 4, no TPDO3/4.
  src.add_slave(7, 0x0B07, {mod("12 in", 12, 0), mod("28 in", 28, 0)});
  src.add_slave(8, 0x0B08, {mod("12 in", 12, 0)});
  for (std::uint8_t i = 0; i < 40; ++i) src.data(7).inputs[i] = i;
  for (std::uint8_t i = 0; i < 12; ++i) src.data(8).inputs[i] = i;
  make();
  EXPECT_EQ(gw->warnings(), (std::vector<std::string>{
                                "slave 7 (node 7): input octets 32..39 are not mapped (TPDO1..4 "
                                "carry 32 octets)"}));
  start();
  EXPECT_EQ(log(), (Log{"0ms 707#00", "0ms 187#0001020304050607", "0ms 287#08090A0B0C0D0E0F",
                        "0ms 387#1011121314151617", "0ms 487#18191A1B1C1D1E1F", "0ms 708#00",
                        "0ms 188#0001020304050607", "0ms 288#08090A0B"}));
  rec.clear();
  at(20 * ms + half_ms, [&] {
    src.data(7).inputs[9] = 0x99;
    src.data(7).inputs[35] = 0x35;  // not mapped: no frame
  });
  run_to(30 * ms);
  EXPECT_EQ(log(), (Log{"21ms 287#08990A0B0C0D0E0F"}));
}

TEST_F(CanopenGatewayTest, TimesCountFromTheStartInstant) {
  add_slave5();
  make();
  run_to(7 * ms);
  start();  // t0 = 7 ms: cyclic TPDOs at 107, 207 ms; the first heartbeat at 1007 ms
  run_to(1100 * ms);
  const Log l = log();
  ASSERT_GE(l.size(), 5u);
  EXPECT_EQ((Log{l[0], l[1], l[2], l[3]}), (Log{"7ms 705#00", "7ms 185#0102030405",
                                               "107ms 185#0102030405", "207ms 185#0102030405"}));
  EXPECT_EQ(log({"705"}), (Log{"7ms 705#00", "1007ms 705#05"}));
}

TEST_F(CanopenGatewayTest, AnRpdoSentInsideATpdoDeliveryIsApplied) {
  // A port that answers every TPDO at once with an RPDO (a PLC echoing inputs to outputs),
  // inside the gateway's own send.
  src.add_slave(5, 0x0A03, {mod("16 in", 16, 0), mod("2DO", 0, 2)});
  for (std::uint8_t i = 0; i < 16; ++i) src.data(5).inputs[i] = i;
  CanHub::PortId plc = 0;
  plc = hub.add_port("plc", [&](const CanFrame& f, bus::Ticks now) {
    if (f.id != 0x185) return;
    CanFrame r = frame("205#0000");
    r.data[0] = f.data[7];
    r.data[1] = f.data[6];
    hub.send(plc, r, now);
  });
  make();
  start();
  // TPDO2 (octets 8..15) still goes out whole after the RPDO handler ran inside TPDO1's send.
  EXPECT_EQ(log({"185", "285", "205"}),
            (Log{"0ms 185#0001020304050607", "0ms 205#0706", "0ms 285#08090A0B0C0D0E0F"}));
  EXPECT_EQ(src.data(5).outputs, (std::vector<std::uint8_t>{7, 6}));
  EXPECT_EQ(gw->stats().rpdo_received, 1u);
}

// --- heartbeat, boot-up, EMCY ------------------------------------------------------------------

TEST_F(CanopenGatewayTest, HeartbeatEverySecondWithTheDpState) {
  add_slave5();
  make();
  start();
  auto& st = src.data(5).status;
  using S = dp::SlaveStatusState;
  at(3500 * ms + half_ms, [&] { src.command(dp::MasterMode::Clear); });
  at(4500 * ms + half_ms, [&] {
    src.command(dp::MasterMode::Operate);
    st.state = S::Prm;  // parameterising: pre-operational
    st.data_valid = false;
  });
  at(5500 * ms + half_ms, [&] { st.state = S::NotPresent; });  // no heartbeat at all
  at(6500 * ms + half_ms, [&] {
    src.command(dp::MasterMode::Stop);
    st.state = S::Inactive;
  });
  at(7500 * ms + half_ms, [&] {
    src.command(dp::MasterMode::Operate);
    st.state = S::DataExchange;
    st.data_valid = true;
  });
  run_to(8500 * ms);
  // 0x05 operational, 0x7F pre-operational, 0x04 stopped, 0x00 boot-up (at the change tick
  // after the return to data exchange: 7501 ms).
  EXPECT_EQ(log({"705"}), (Log{"0ms 705#00", "1000ms 705#05", "2000ms 705#05", "3000ms 705#05",
                               "4000ms 705#7F", "5000ms 705#7F", "7000ms 705#04", "7501ms 705#00",
                               "8000ms 705#05"}));
  EXPECT_EQ(gw->stats().heartbeat_sent, 7u);
  EXPECT_EQ(gw->stats().bootup_sent, 2u);
}

TEST_F(CanopenGatewayTest, StationFailureEmcyNoStaleTpdosBootUpAndResetOnReturn) {
  add_slave5();
  make();
  start();
  auto& d = src.data(5);
  at(50 * ms + half_ms, [&] {
    d.status.state = dp::SlaveStatusState::NotPresent;
    d.status.data_valid = false;
    d.status.failures = 1;
  });
  at(150 * ms + half_ms, [&] {
    d.status.state = dp::SlaveStatusState::DataExchange;
    d.status.data_valid = true;
    d.status.returns = 1;
    d.inputs = {0x0A, 0x0B, 0x0C, 0x0D, 0x0E};
  });
  run_to(60 * ms);
  EXPECT_EQ(gw->error_register(5), 0x11);  // generic + communication
  run_to(250 * ms);
  // EMCY 0x080 + 5: error code 0x8130 LE = 30 81, error register 0x10 | 0x01 = 0x11,
  // manufacturer octet 1 = DP state code 7 (NotPresent), then four zeros. No TPDO at 100 ms
  // (stale data is not sent). On the return: boot-up, error reset 0x0000 with error register
  // 0, then the fresh inputs.
  EXPECT_EQ(log(), (Log{"0ms 705#00", "0ms 185#0102030405", "51ms 085#3081110700000000",
                        "151ms 705#00", "151ms 085#0000000000000000", "151ms 185#0A0B0C0D0E",
                        "200ms 185#0A0B0C0D0E"}));
  EXPECT_EQ(gw->error_register(5), 0);
  EXPECT_EQ(gw->stats().emcy_sent, 2u);
}

TEST_F(CanopenGatewayTest, FailureAndReturnBetweenTwoTicksStillReported) {
  add_slave5();
  make();
  start();
  // The master counted a failure and a return, but both ticks see data exchange.
  at(10 * ms + half_ms, [&] {
    src.data(5).status.failures = 1;
    src.data(5).status.returns = 1;
  });
  run_to(20 * ms);
  EXPECT_EQ(log({"085", "705"}), (Log{"0ms 705#00", "11ms 085#3081110600000000", "11ms 705#00",
                                      "11ms 085#0000000000000000"}));
}

TEST_F(CanopenGatewayTest, MasterStopIsNoStationFailure) {
  add_slave5();
  make();
  start();
  at(50 * ms + half_ms, [&] {
    src.command(dp::MasterMode::Stop);
    src.data(5).status.state = dp::SlaveStatusState::Inactive;
    src.data(5).status.data_valid = false;
  });
  run_to(1500 * ms);
  EXPECT_EQ(log(), (Log{"0ms 705#00", "0ms 185#0102030405", "1000ms 705#04"}));
}

TEST_F(CanopenGatewayTest, ExtDiagEmcyOnChangeAndClearWithRemainingErrorRegister) {
  add_slave5();
  make();
  start();
  auto& st = src.data(5).status;
  // Slave_Diag: octet 1 = 0x08 Ext_Diag, 2 = 0x0C, 3 = 0x00, master 2, ident 0A03, then an
  // identifier-related block 0x43 (header: 01 = identifier, length 3) 0x01 0x00.
  at(20 * ms + half_ms, [&] { st.diag = {0x08, 0x0C, 0x00, 0x02, 0x0A, 0x03, 0x43, 0x01, 0x00}; });
  at(40 * ms + half_ms, [&] { st.diag[7] = 0x02; });  // changed extended diagnosis
  at(60 * ms + half_ms, [&] { st.diag = {0x00, 0x0C, 0x00, 0x02, 0x0A, 0x03}; });
  at(80 * ms + half_ms, [&] { st.diag = {0x08, 0x0C, 0x00, 0x02, 0x0A, 0x03}; });  // no ext octets
  at(100 * ms + half_ms, [&] {
    st.state = dp::SlaveStatusState::NotPresent;
    st.data_valid = false;
  });
  at(120 * ms + half_ms, [&] {
    st.state = dp::SlaveStatusState::DataExchange;
    st.data_valid = true;
  });
  run_to(130 * ms);
  // 0xFF00 LE = 00 FF; error register 0x80 | 0x01 = 0x81; manufacturer = Slave_Diag octets 1,
  // 2, 3 and the first two extended octets (octets 7, 8), 0 where absent. The failure while
  // Ext_Diag is active: 0x8130 with 0x80 | 0x10 | 0x01 = 0x91; its reset keeps 0x81.
  EXPECT_EQ(log({"085"}), (Log{"21ms 085#00FF81080C004301", "41ms 085#00FF81080C004302",
                               "61ms 085#0000000000000000", "81ms 085#00FF81080C000000",
                               "101ms 085#3081910700000000", "121ms 085#0000810000000000"}));
  EXPECT_EQ(gw->error_register(5), 0x81);
}

// --- RPDOs -------------------------------------------------------------------------------------

TEST_F(CanopenGatewayTest, RpdoRewritesEveryTouchedModuleWhole) {
  add_slave5();
  make();
  start();
  using W = std::vector<std::uint8_t>;
  send("205#AA");  // octet 0 only: module "2DO" (octets 0..1), octet 1 kept
  ASSERT_EQ(src.writes().size(), 1u);
  EXPECT_EQ(src.writes()[0].module, 1u);
  EXPECT_EQ(src.writes()[0].data, (W{0xAA, 0x00}));
  send("205#1122334455");  // octets 0..4: "2DO" whole and "4AO" (2..5) whole, octet 5 kept
  ASSERT_EQ(src.writes().size(), 3u);
  EXPECT_EQ(src.writes()[1].module, 1u);
  EXPECT_EQ(src.writes()[1].data, (W{0x11, 0x22}));
  EXPECT_EQ(src.writes()[2].module, 2u);
  EXPECT_EQ(src.writes()[2].data, (W{0x33, 0x44, 0x55, 0x00}));
  send("205#0102030405060708");  // 8 octets for 6 mapped: octets 6, 7 dropped
  ASSERT_EQ(src.writes().size(), 5u);
  EXPECT_EQ(src.writes()[4].data, (W{0x03, 0x04, 0x05, 0x06}));
  EXPECT_EQ(src.data(5).outputs, (W{1, 2, 3, 4, 5, 6}));
  send("305#FF");  // RPDO2: octets 8.. do not exist
  send("205#");    // DLC 0: nothing to write
  EXPECT_EQ(src.writes().size(), 5u);
  EXPECT_EQ(gw->stats().rpdo_received, 4u);
  EXPECT_EQ(gw->stats().rpdo_refused, 1u);
  EXPECT_EQ(log(), (Log{"0ms 705#00", "0ms 185#0102030405"}));  // nothing sent in reply
}

TEST_F(CanopenGatewayTest, RpdoForReadOnlyOutputsIsIgnoredAndCounted) {
  src.add_slave(9, 0x0B09, {mod("2DO", 0, 2)}).outputs_writable = false;
  make();
  start();
  send("209#0102");
  EXPECT_TRUE(src.writes().empty());
  EXPECT_EQ(gw->stats().rpdo_refused, 1u);
  EXPECT_EQ(gw->stats().rpdo_received, 0u);
}

// --- SDO ---------------------------------------------------------------------------------------

TEST_F(CanopenGatewayTest, SdoUploadOfEveryObject) {
  add_slave5();
  auto& st = src.data(5).status;
  st.data_exchanges = 0x12345678;
  st.failures = 2;
  st.diag = {0x00, 0x0C, 0x00, 0x02, 0x0A, 0x03};
  make();
  start();
  run_to(10 * ms);
  rec.clear();
  // Request 0x40 | index LE | sub; response 0x43 | (4 - size) << 2: u32 → 0x43, u16 → 0x4B,
  // u8 → 0x4F; data LE. Identity sub 1..4 are UNSIGNED32 (CiA 301): product code = ident
  // 0x0A03 → 03 0A 00 00; serial = address 5. 0x1017 = 1000 ms = 0x03E8 → E8 03.
  const std::pair<const char*, const char*> cases[] = {
      {"605#4000100000000000", "585#4300100000000000"},  // 0x1000 device type u32 0
      {"605#4001100000000000", "585#4F01100000000000"},  // 0x1001 error register u8 0
      {"605#4017100000000000", "585#4B171000E8030000"},  // 0x1017 heartbeat u16 1000
      {"605#4018100000000000", "585#4F18100004000000"},  // 0x1018 sub 0 = 4
      {"605#4018100100000000", "585#4318100100000000"},  // vendor id 0
      {"605#4018100200000000", "585#43181002030A0000"},  // product code = ident
      {"605#4018100300000000", "585#4318100300000000"},  // revision 0
      {"605#4018100400000000", "585#4318100405000000"},  // serial = address
      {"605#4000200000000000", "585#4F00200007000000"},  // 0x2000 sub 0: 7 subs
      {"605#4000200100000000", "585#4F00200106000000"},  // DP state 6 DataExchange
      {"605#4000200200000000", "585#4F00200201000000"},  // flags: data valid
      {"605#4000200300000000", "585#4300200378563412"},  // life counter u32 0x12345678
      {"605#4000200400000000", "585#4B002004030A0000"},  // ident u16
      {"605#4000200500000000", "585#4F002005FF000000"},  // active channel: none
      {"605#4000200600000000", "585#4300200602000000"},  // failures u32 2
      {"605#4000200700000000", "585#4F00200706000000"},  // diag length 6
      {"605#4001200000000000", "585#4F01200006000000"},  // 0x2001 sub 0 = length
      {"605#4001200200000000", "585#4F0120020C000000"},  // sub 2 = Slave_Diag octet 2
      {"605#4001200600000000", "585#4F01200603000000"},  // sub 6 = octet 6 (ident low)
  };
  for (const auto& [req, resp] : cases) {
    rec.clear();
    send(req);
    EXPECT_EQ(log(), (Log{"10ms " + std::string(resp)})) << req;
  }
  EXPECT_EQ(gw->stats().sdo_received, std::size(cases));
  EXPECT_EQ(gw->stats().sdo_sent, std::size(cases));
  EXPECT_EQ(gw->stats().sdo_aborts, 0u);
}

TEST_F(CanopenGatewayTest, SdoDownloadOfHeartbeatTimeRestartsTheProducer) {
  add_slave5();
  make();
  start();
  run_to(1200 * ms);
  // 0x2B = 2-octet expedited download; 500 = 0x01F4 → F4 01. Response 0x60.
  send("605#2B171000F4010000");
  run_to(2300 * ms);
  // The new period counts from the write: 1700, 2200 ms (not 2000).
  EXPECT_EQ(log({"705", "585"}), (Log{"0ms 705#00", "1000ms 705#05", "1200ms 585#6017100000000000",
                                      "1700ms 705#05", "2200ms 705#05"}));
  EXPECT_EQ(gw->heartbeat_ms(5), 500);
  rec.clear();
  send("605#2B17100000000000");  // 0 disables the heartbeat
  run_to(6000 * ms);
  EXPECT_EQ(log({"705"}), Log{});
  send("605#4017100000000000");
  EXPECT_EQ(log({"585"}).back(), "6000ms 585#4B17100000000000");
}

TEST_F(CanopenGatewayTest, SdoAbortsWithTheirCodes) {
  add_slave5();
  make();
  start();
  rec.clear();
  // Abort: 0x80 | index LE | sub | code LE. 0x06020000 → 00 00 02 06, 0x06090011 → 11 00 09 06,
  // 0x06010002 → 02 00 01 06, 0x06070010 → 10 00 07 06, 0x05040001 → 01 00 04 05.
  const std::pair<const char*, const char*> cases[] = {
      {"605#4000300000000000", "585#8000300000000206"},  // no object 0x3000
      {"605#4018100500000000", "585#8018100511000906"},  // 0x1018 sub 5
      {"605#4000200800000000", "585#8000200811000906"},  // 0x2000 sub 8
      {"605#2F00100001000000", "585#8000100002000106"},  // write device type: read-only
      {"605#23171000F4010000", "585#8017100010000706"},  // 4 octets to a u16
      {"605#2B171001F4010000", "585#8017100111000906"},  // 0x1017 sub 1
      {"605#2117100002000000", "585#8017100001000405"},  // segmented download
      {"605#A000200000000000", "585#8000200001000405"},  // block upload
      {"605#6000000000000000", "585#8000000001000405"},  // upload segment without transfer
      {"605#401810", "585#8018100001000405"},            // 3 octets: not an SDO frame
  };
  for (const auto& [req, resp] : cases) {
    rec.clear();
    send(req);
    EXPECT_EQ(log(), (Log{"0ms " + std::string(resp)})) << req;
  }
  rec.clear();
  send("605#8000200000000405");  // the client aborts: no response
  EXPECT_TRUE(rec.empty());
  EXPECT_EQ(gw->stats().sdo_received, std::size(cases) + 1);
  EXPECT_EQ(gw->stats().sdo_aborts, std::size(cases));
  EXPECT_EQ(gw->heartbeat_ms(5), 1000);  // nothing was written
}

// --- what is not for us; map; lifetime ---------------------------------------------------------

TEST_F(CanopenGatewayTest, FramesNotForUsAreIgnoredAndCounted) {
  add_slave5();
  make();
  send("205#01");  // before start(): the gateway is not on the bus yet
  start();
  send("185#01");       // another producer's TPDO with our node id
  send("206#01");       // RPDO of a node we do not serve
  send("705#05");       // someone else's heartbeat
  send("18FF0005#01");  // extended identifier
  CanFrame rtr = frame("605#");
  rtr.rtr = true;
  send(rtr);
  EXPECT_EQ(gw->stats().ignored, 6u);
  EXPECT_TRUE(src.writes().empty());
  EXPECT_EQ(log().size(), 2u);  // boot-up and TPDO only
}

TEST_F(CanopenGatewayTest, NodeMapRemapsAndWarns) {
  for (int a : {0, 5, 6, 7, 8})
    src.add_slave(static_cast<std::uint8_t>(a), 0x0B00, {mod("1 in", 1, 0)});
  src.data(6).inputs = {0x66};
  CanopenOptions o;
  o.node_ids = {{6, 5}, {7, 0}, {9, 30}};
  make(o);
  // Explicit entries first (6 → 5; 7 → 0 is invalid), then defaults (0 is invalid, 5 is taken,
  // 8 → 8), then entries for unknown addresses.
  EXPECT_EQ(gw->warnings(),
            (std::vector<std::string>{
                "slave 7: node id 0 is outside 1..127; the slave is not mapped",
                "slave 0: node id 0 is outside 1..127; the slave is not mapped",
                "slave 5: node id 5 is already slave 6's; the slave is not mapped",
                "node map: address 9 is not a slave of this master system (node 30 ignored)"}));
  ASSERT_EQ(gw->map().nodes.size(), 2u);
  start();
  EXPECT_EQ(log(), (Log{"0ms 705#00", "0ms 185#66", "0ms 708#00", "0ms 188#00"}));
}

TEST_F(CanopenGatewayTest, MapAsText) {
  add_slave5();
  const auto m = build_canopen_map(src.slaves(), {});
  EXPECT_EQ(to_text(m),
            "node 5 = slave 5 \"fake\": 5 input octets, 6 output octets\n"
            "  TPDO1 185  inputs 0..4\n"
            "  RPDO1 205  outputs 0..5\n"
            "  EMCY 085  heartbeat 705  SDO 605/585\n");
}

TEST_F(CanopenGatewayTest, DestructorRemovesItsPort) {
  add_slave5();
  make();
  EXPECT_EQ(hub.ports(), 2u);
  gw.reset();
  EXPECT_EQ(hub.ports(), 1u);
}

}  // namespace
}  // namespace pbvbus::gateways
