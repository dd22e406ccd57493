// Mutant slaves at the FDL level (PassiveMutation, devices/slave_mutant.hpp): tsdr_too_late,
// ignore_min_tsdr, ignore_fcb. Each test runs the same golden frames against a conformant
// PassiveStation and a mutated one on a real Line, and checks the replies' bytes and start times
// in bit times at 1.5 Mbit/s (requests and replies written by hand, protocol-facts.md Appendix 1).

#include <gtest/gtest.h>

#include <functional>
#include <memory>

#include "fdl_station_helpers.hpp"
#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/fdl/passive_station.hpp"

namespace pbvbus::fdl {
namespace {

using pbvbus::test::bytes_from_hex;
using pbvbus::test::FrameRecorder;
using test::ScriptDevice;

class FnUser final : public ResponderUser {
 public:
  void on_request(const Indication& ind, Reply& reply) override {
    ++calls;
    if (handler) handler(ind, reply);
  }
  std::function<void(const Indication&, Reply&)> handler;
  int calls = 0;
};

/// A scripted master and one passive station at address 10 on a 1.5 Mbit/s line.
struct Rig {
  explicit Rig(const PassiveMutation& m, std::uint32_t tsdr = 0)
      : station(10, params, user, tsdr) {
    station.set_mutation(m);
    line.add_tap(rec);
    line.attach(master);
    line.attach(station);
    line.start();
  }
  static bus::Ticks at(std::int64_t b) { return bus::bits_to_ticks(b, bus::Baud::k1_5M); }
  void send(std::int64_t at_bits, std::string_view hex) {
    master.send(at(at_bits), bytes_from_hex(hex));
  }
  void run() { sched.run_until(at(10'000)); }

  BusParams params = BusParams::defaults(bus::Baud::k1_5M);  // min TSDR 11, max TSDR 150
  FnUser user;
  bus::Scheduler sched;
  bus::Line line{sched, "dp", bus::Baud::k1_5M};
  FrameRecorder rec;
  ScriptDevice master;
  PassiveStation station;
};

// Request FDL Status 1 -> 10: 10 0A 01 49 FCS 16, FCS = 0A+01+49 = 0x54; 6 octets = 66 bits.
// Answer (FDL, not the user): 10 01 0A 00 FCS 16, FCS = 01+0A+00 = 0x0B.
constexpr std::string_view kFdlStatus = "10 0A 01 49 54 16";
constexpr std::string_view kFdlStatusReply = "10 01 0A 00 0B 16";

// --- tsdr_too_late ------------------------------------------------------------------------------

TEST(PassiveMutation, TsdrTooLateAnswersBeyondMaxTsdr) {
  // The model passes MaxTsdr_1.5M (150) + 20 = 170 t_bit.
  ASSERT_EQ(BusParams::defaults(bus::Baud::k1_5M).max_tsdr, 150u);
  // Conformant: a station asking for 170 is held to max TSDR 150.
  Rig good({}, 170);
  good.send(1000, kFdlStatus);
  good.run();
  ASSERT_EQ(good.rec.size(), 2u);
  EXPECT_EQ(good.rec.hex(1), kFdlStatusReply);
  EXPECT_EQ(good.rec.start_bits(1), 1000 + 66 + 150);

  PassiveMutation m;
  m.fixed_tsdr = 170;
  Rig bad(m, 170);
  // Also a user request: Slave_Diag 1 -> 10 (Appendix 1, 11 octets = 121 bits), answered SC.
  bad.user.handler = [](const Indication&, Reply& r) { r.short_ack(); };
  bad.send(1000, kFdlStatus);
  bad.send(2000, "68 05 05 68 8A 81 6D 3C 3E F2 16");
  bad.run();
  ASSERT_EQ(bad.rec.size(), 4u);
  EXPECT_EQ(bad.rec.hex(1), kFdlStatusReply);
  EXPECT_EQ(bad.rec.start_bits(1), 1000 + 66 + 170) << "(MaxTsdr + 20) after the request";
  EXPECT_EQ(bad.rec.hex(3), "E5");
  EXPECT_EQ(bad.rec.start_bits(3), 2000 + 121 + 170);
  EXPECT_EQ(bad.station.response_delay(), 170u);
}

// --- ignore_min_tsdr ----------------------------------------------------------------------------

TEST(PassiveMutation, IgnoreMinTsdrKeepsItsOwnDelay) {
  // Appendix 1 Set_Prm 1 -> 10 (18 octets = 198 bits); the user asks for min TSDR 40 (a test
  // value; the frame's octet 4 says 11).
  const std::string_view set_prm = "68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16";
  for (const bool mutated : {false, true}) {
    SCOPED_TRACE(mutated ? "mutant" : "conformant");
    PassiveMutation m;
    m.ignore_min_tsdr = mutated;
    Rig rig(m);
    rig.user.handler = [](const Indication& ind, Reply& r) {
      r.short_ack();
      if (ind.dsap == 61) r.new_min_tsdr = 40;
    };
    rig.send(1000, set_prm);
    rig.send(2000, kFdlStatus);
    rig.run();
    ASSERT_EQ(rig.rec.size(), 4u);
    EXPECT_EQ(rig.rec.hex(1), "E5");
    EXPECT_EQ(rig.rec.start_bits(1), 1000 + 198 + 11);
    EXPECT_EQ(rig.rec.hex(3), kFdlStatusReply);
    EXPECT_EQ(rig.rec.start_bits(3), 2000 + 66 + (mutated ? 11 : 40));
    EXPECT_EQ(rig.station.min_tsdr(), mutated ? 11u : 40u);
  }
}

// --- ignore_fcb ---------------------------------------------------------------------------------

TEST(PassiveMutation, IgnoreFcbExecutesRepeats) {
  // The user answers Slave_Diag with one octet = its call count, so a repeat answered from the
  // stored reply and a re-executed one differ on the wire. Reply SD2, LE = DA SA FC DSAP SSAP +
  // 1 octet = 6: 68 06 06 68 81 8A 08 3E 3C NN,
  // FCS = 81+8A+08+3E+3C+NN = 0x18D + NN -> 8E, 8F, 90, 91 for NN = 1..4.
  for (const bool mutated : {false, true}) {
    SCOPED_TRACE(mutated ? "mutant" : "conformant");
    PassiveMutation m;
    m.ignore_fcb = mutated;
    Rig rig(m);
    rig.user.handler = [&rig](const Indication&, Reply& r) {
      const std::uint8_t d[] = {static_cast<std::uint8_t>(rig.user.calls)};
      r.respond(ResponseStatus::DL, d);
    };
    // First frame FC 6D (FCV=0, FCB=1), then 5D (FCV=1, FCB=0: new), 5D again (a repeat),
    // then 7D (FCV=1, FCB=1: new). FCS 8A+81+FC+3C+3E: F2, E2, E2, 02.
    rig.send(500, "68 05 05 68 8A 81 6D 3C 3E F2 16");
    rig.send(1500, "68 05 05 68 8A 81 5D 3C 3E E2 16");
    rig.send(2500, "68 05 05 68 8A 81 5D 3C 3E E2 16");
    rig.send(3500, "68 05 05 68 8A 81 7D 3C 3E 02 16");
    rig.run();
    ASSERT_EQ(rig.rec.size(), 8u);
    EXPECT_EQ(rig.rec.hex(1), "68 06 06 68 81 8A 08 3E 3C 01 8E 16");
    EXPECT_EQ(rig.rec.hex(3), "68 06 06 68 81 8A 08 3E 3C 02 8F 16");
    if (!mutated) {
      EXPECT_EQ(rig.rec.hex(5), "68 06 06 68 81 8A 08 3E 3C 02 8F 16") << "stored reply";
      EXPECT_EQ(rig.rec.hex(7), "68 06 06 68 81 8A 08 3E 3C 03 90 16");
      EXPECT_EQ(rig.user.calls, 3);
      EXPECT_EQ(rig.station.stats().repeats, 1u);
    } else {
      EXPECT_EQ(rig.rec.hex(5), "68 06 06 68 81 8A 08 3E 3C 03 90 16") << "executed again";
      EXPECT_EQ(rig.rec.hex(7), "68 06 06 68 81 8A 08 3E 3C 04 91 16");
      EXPECT_EQ(rig.user.calls, 4);
      EXPECT_EQ(rig.station.stats().repeats, 0u);
    }
    // The timing is conformant either way: min TSDR after the 121-bit request.
    EXPECT_EQ(rig.rec.start_bits(5), 2500 + 121 + 11);
  }
}

}  // namespace
}  // namespace pbvbus::fdl
