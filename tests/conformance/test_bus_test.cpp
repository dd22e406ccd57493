// TestBus: the tester's line. A SlaveModel of examples/gsd/PBVB0A01.gsd at address 3, tester 1,
// 1.5 Mbit/s with the DP defaults (TSL 300, min TSDR 11, max TSDR 150 = the GSD's MaxTsdr_1.5M).
// Every frame and time is worked out by hand below (protocol-facts.md §B.1, §B.3, Appendix 1).

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "pbvbus/conformance/test_bus.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"

namespace pbvbus::conformance {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Request FDL Status, SD1: 10 DA SA FC FCS 16 with DA 3, SA 1, FC 0x49 (request bit 0x40 |
// function 9, FCV = FCB = 0); FCS = 03 + 01 + 49 = 0x4D.
const Bytes kFdlStatus3 = {0x10, 0x03, 0x01, 0x49, 0x4D, 0x16};
// The passive station's reply: SD1, DA 1 (mirrors SA), SA 3, FC = response (bit 6 = 0), station
// type bits 5..4 = 00 (slave), status 0 (OK) → FC 0x00; FCS = 01 + 03 + 00 = 0x04 (Appendix 1).
const Bytes kFdlStatusReply = {0x10, 0x01, 0x03, 0x00, 0x04, 0x16};
// The same request to the absent address 9: FCS = 09 + 01 + 49 = 0x53.
const Bytes kFdlStatus9 = {0x10, 0x09, 0x01, 0x49, 0x53, 0x16};
// Slave_Diag, SD2 with DSAP 60 (0x3C) / SSAP 62 (0x3E), no DU: LE = DA SA FC DSAP SSAP = 5;
// DA 0x83 (3 | EXT), SA 0x81 (1 | EXT), FC 0x4D (SRD high, FCV = FCB = 0);
// FCS = 83 + 81 + 4D + 3C + 3E = 0x1CB → 0xCB.
const Bytes kSlaveDiag3 = {0x68, 0x05, 0x05, 0x68, 0x83, 0x81, 0x4D, 0x3C, 0x3E, 0xCB, 0x16};

std::shared_ptr<devices::GsdFile> gsd_0a01() {
  auto r = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A01.gsd");
  EXPECT_TRUE(r.ok());
  return std::make_shared<devices::GsdFile>(*r.file);
}

fdl::BusParams params_1m5() {
  fdl::BusParams p = fdl::BusParams::defaults(bus::Baud::k1_5M);
  p.max_tsdr = 150;  // MaxTsdr_1.5M of PBVB0A01
  return p;
}

struct Rig {
  std::shared_ptr<devices::GsdFile> gsd = gsd_0a01();
  std::unique_ptr<devices::SlaveModel> model;
  std::unique_ptr<TestBus> bus;

  explicit Rig(TestBusOptions opt, fdl::BusParams model_params = params_1m5()) {
    devices::SlaveModelOptions o;
    o.address = 3;
    o.bus_params = model_params;
    auto b = devices::SlaveModel::build(*gsd, {devices::ModuleChoice::at(0)}, o);
    EXPECT_TRUE(b.ok());
    model = std::move(b.model);
    bus = std::make_unique<TestBus>(std::move(opt));
    bus->attach_dut(*model, "slave 3");
    bus->start();
  }
  ~Rig() { bus.reset(); }
  std::int64_t bits(bus::Ticks t) const { return bus::ticks_to_bits(t, bus::Baud::k1_5M); }
};

TestBusOptions fast_options() {
  TestBusOptions o;
  o.params = params_1m5();
  return o;
}

TEST(TestBus, FdlStatusIsAnsweredMinTsdrAfterTheRequest) {
  Rig rig(fast_options());
  const Exchange e = rig.bus->request(kFdlStatus3, "FDL_Status");
  // The line was never used: the tester still keeps TSYN = 33 bit times from time 0, so the
  // request starts at 33 and its 6 octets × 11 bits end at 33 + 66 = 99 bit times.
  EXPECT_EQ(rig.bits(e.request_start), 33);
  EXPECT_EQ(rig.bits(e.request_end), 99);
  ASSERT_TRUE(e.answered);
  EXPECT_EQ(e.response, kFdlStatusReply);
  EXPECT_EQ(e.response_flags, 0u);
  // min TSDR = 11: reply start 99 + 11 = 110, end 110 + 66 = 176.
  EXPECT_EQ(e.tsdr_bits, 11);
  EXPECT_EQ(rig.bits(e.response_start), 110);
  EXPECT_EQ(rig.bits(e.response_end), 176);
  EXPECT_EQ(e.sender, 1);
  EXPECT_EQ(e.note, "FDL_Status");
  // The call returns when the reply has ended.
  EXPECT_EQ(rig.bits(rig.bus->now()), 176);
  EXPECT_EQ(rig.bus->transcript().size(), 1u);
  EXPECT_TRUE(rig.bus->extra_frames().empty());
}

TEST(TestBus, AbsentAddressGetsNoReplyAndReturnsAfterExactlyTsl) {
  Rig rig(fast_options());
  const Exchange e = rig.bus->request(kFdlStatus9, "nobody at 9");
  EXPECT_FALSE(e.answered);
  EXPECT_EQ(e.tsdr_bits, -1);
  EXPECT_TRUE(e.response.empty());
  // Request 33..99 bit times; slot time TSL = 300 → the call returns at 99 + 300 = 399.
  EXPECT_EQ(rig.bits(e.request_end), 99);
  EXPECT_EQ(rig.bus->now(), e.request_end + bus::bits_to_ticks(300, bus::Baud::k1_5M));
}

TEST(TestBus, SecondRequestKeepsTsynAfterTheReply) {
  Rig rig(fast_options());
  const Exchange a = rig.bus->request(kFdlStatus3);
  const Exchange b = rig.bus->request(kSlaveDiag3, "Slave_Diag");
  // a's reply ends at 176 (previous test); b starts TSYN = 33 later: 209.
  EXPECT_EQ(rig.bits(a.response_end), 176);
  EXPECT_EQ(rig.bits(b.request_start), 209);
  EXPECT_EQ(b.request_start - a.response_end, bus::bits_to_ticks(33, bus::Baud::k1_5M));
  // 11 octets: 209 + 121 = 330; the unparameterised diag reply 11 bit times later.
  EXPECT_EQ(rig.bits(b.request_end), 330);
  ASSERT_TRUE(b.answered);
  EXPECT_EQ(b.tsdr_bits, 11);
  // Reply: SD3 (DU 02 05 00 FF 0A 01 + 2 SAPs = 8 octets): A2 DA SA FC DSAP SSAP DU FCS 16 with
  // DA 0x81, SA 0x83, FC 0x08 (DL), DSAP 3E, SSAP 3C (mirrored), DU 02 05 00 FF 0A 01;
  // FCS = 81+83+08+3E+3C+02+05+00+FF+0A+01 = 0x297 → 0x97.
  const Bytes diag = {0xA2, 0x81, 0x83, 0x08, 0x3E, 0x3C, 0x02, 0x05,
                      0x00, 0xFF, 0x0A, 0x01, 0x97, 0x16};
  EXPECT_EQ(b.response, diag);
  ASSERT_EQ(rig.bus->transcript().size(), 2u);
  EXPECT_EQ(rig.bus->since(1).size(), 1u);
  EXPECT_EQ(rig.bus->since(5).size(), 0u);
}

TEST(TestBus, NotBeforeDelaysTheRequest) {
  Rig rig(fast_options());
  const bus::Ticks at = bus::bits_to_ticks(1000, bus::Baud::k1_5M);
  const Exchange e = rig.bus->request(kFdlStatus3, {}, at);
  EXPECT_EQ(e.request_start, at);
  EXPECT_EQ(e.tsdr_bits, 11);
}

TEST(TestBus, AReplyThatStartsInTimeIsAwaitedToItsEnd) {
  // The tester's slot time is only 50 bit times: the diag reply (SD3, 14 octets = 154 bits)
  // starts 11 bit times after the request but ends 165 bit times after it, long after TSL.
  TestBusOptions o = fast_options();
  o.params.tsl = 50;
  Rig rig(o);
  const Exchange e = rig.bus->request(kSlaveDiag3);
  ASSERT_TRUE(e.answered);
  EXPECT_EQ(e.tsdr_bits, 11);
  EXPECT_EQ(e.response.size(), 14u);
  EXPECT_EQ(e.response_end - e.request_end, bus::bits_to_ticks(11 + 154, bus::Baud::k1_5M));
  EXPECT_EQ(rig.bus->now(), e.response_end);
}

TEST(TestBus, AReplyAfterTheSlotTimeIsAnExtraFrame) {
  // The model answers after min TSDR 60 (its own bus parameters), the tester's TSL is 40: the
  // reply starts 60 bit times after the request, 20 after the window, and is no reply.
  TestBusOptions o = fast_options();
  o.params.tsl = 40;
  fdl::BusParams mp = params_1m5();
  mp.min_tsdr = 60;
  Rig rig(o, mp);
  const Exchange e = rig.bus->request(kFdlStatus3);
  EXPECT_FALSE(e.answered);
  // Idle long enough for that frame to end: it is recorded as extra.
  rig.bus->idle(bus::bits_to_ticks(200, bus::Baud::k1_5M));  // request end + 40 + 200 > 60 + 66
  ASSERT_EQ(rig.bus->extra_frames().size(), 1u);
  const auto& x = rig.bus->extra_frames()[0];
  EXPECT_EQ(x.bytes, kFdlStatusReply);
  EXPECT_EQ(x.start - e.request_end, bus::bits_to_ticks(60, bus::Baud::k1_5M));
}

TEST(TestBus, PoweredOffDutDoesNotAnswerAndTheEventIsRecorded) {
  Rig rig(fast_options());
  rig.bus->set_dut_power(false);
  const Exchange e = rig.bus->request(kFdlStatus3);
  EXPECT_FALSE(e.answered);
  ASSERT_FALSE(rig.bus->extra_frames().empty());
  EXPECT_EQ(rig.bus->extra_frames()[0].event.rfind("power off", 0), 0u);
  rig.bus->set_dut_power(true);
  EXPECT_TRUE(rig.bus->request(kFdlStatus3).answered);
}

TEST(TestBus, CutBetweenTesterAndDutSilencesIt) {
  Rig rig(fast_options());
  rig.bus->set_bus_interrupted(true);
  EXPECT_FALSE(rig.bus->request(kFdlStatus3).answered);
  rig.bus->set_bus_interrupted(false);
  EXPECT_TRUE(rig.bus->request(kFdlStatus3).answered);
}

TEST(TestBus, SendNoReplyWaitsTsynAfterItsEnd) {
  Rig rig(fast_options());
  // Global_Control broadcast, SDN high: 68 07 07 68 FF 81 46 3A 3E 00 00 FCS 16;
  // FCS = FF+81+46+3A+3E+00+00 = 0x23E → 0x3E (13 octets = 143 bit times).
  const Bytes gc = {0x68, 0x07, 0x07, 0x68, 0xFF, 0x81, 0x46, 0x3A, 0x3E, 0x00, 0x00, 0x3E, 0x16};
  const Exchange e = rig.bus->send_no_reply(gc, "Global_Control");
  EXPECT_FALSE(e.expects_reply);
  EXPECT_FALSE(e.answered);
  EXPECT_EQ(rig.bits(e.request_end - e.request_start), 143);
  EXPECT_EQ(rig.bus->now(), e.request_end + bus::bits_to_ticks(33, bus::Baud::k1_5M));
}

TEST(TestBus, PacedExchangeHasTheSameVirtualTiming) {
  TestBusOptions o = fast_options();
  o.paced = bus::Speed{1, 1};
  Rig rig(o);
  ASSERT_NE(rig.bus->runner(), nullptr);
  const Exchange e = rig.bus->request(kFdlStatus3);
  ASSERT_TRUE(e.answered);
  EXPECT_EQ(e.response, kFdlStatusReply);
  EXPECT_EQ(e.tsdr_bits, 11);
  EXPECT_EQ(rig.bits(e.request_end), 99);
}

TEST(TestBus, PacedWaitForAnAbsentStationEndsAtTheSlotTime) {
  // At 1/1000 the slot time (300 bit times at 1.5 Mbit/s = 200 us virtual) takes 0.2 s of wall
  // time; the call returns with virtual time exactly TSL after the request's end.
  TestBusOptions o = fast_options();
  o.paced = bus::Speed{1, 1000};
  Rig rig(o);
  const auto t0 = std::chrono::steady_clock::now();
  const Exchange e = rig.bus->request(kFdlStatus9);
  EXPECT_FALSE(e.answered);
  EXPECT_EQ(rig.bus->now(), e.request_end + bus::bits_to_ticks(300, bus::Baud::k1_5M));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(30));  // generous bound
}

}  // namespace
}  // namespace pbvbus::conformance
