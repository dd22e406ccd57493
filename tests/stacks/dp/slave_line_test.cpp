// DP slave engine on a real bus::Line behind an FDL PassiveStation: whole frames on the wire
// against the golden frames of protocol-facts.md Appendix 1 (and frames written by hand with
// their FCS worked out in the comments), with reply timing in bit times.
#include <gtest/gtest.h>

#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/passive_station.hpp"

namespace pbvbus::dp {
namespace {

using pbvbus::test::bytes_from_hex;
using pbvbus::test::FrameRecorder;
using Bytes = std::vector<std::uint8_t>;

/// A stand-in master that sends hand-written frames at given times.
class ScriptMaster final : public bus::Device {
 public:
  void on_power_on(bus::Ticks) override {}
  void on_frame(const bus::RxFrame&) override {}
  void on_timer(bus::Ticks) override {}
  void send(bus::Ticks at, const Bytes& b) { port().transmit(at, b); }
};

class SlaveOnLine : public ::testing::Test {
 protected:
  static SlaveConfig make_config() {
    SlaveConfig c;
    c.ident = 0x1234;
    c.modules = {{{0x10}, "1 byte in"}, {{0x20}, "1 byte out"}};
    c.features.set_slave_add = true;
    return c;
  }
  explicit SlaveOnLine(std::uint8_t address = 10)
      : engine(make_config()), station(address, params, engine) {
    line.add_tap(rec);
    line.attach(master, "master 1");
    line.attach(station, "slave");
    line.start();
  }
  bus::Ticks bits(std::int64_t n) const { return bus::bits_to_ticks(n, bus::Baud::k1_5M); }
  /// Sends a request 1000 bit times after the last activity and runs until its answer is out.
  /// Returns the reply frame ("" if none).
  std::string exchange(std::string_view request) {
    const std::size_t before = rec.size();
    m_t = std::max(m_t, sched.now()) + bits(1000);
    master.send(m_t, bytes_from_hex(request));
    m_t += bits(2000);
    sched.run_until(m_t);
    if (rec.size() < before + 1) return "<request lost>";
    if (rec.size() == before + 1) return "";
    return rec.hex(before + 1);
  }
  /// Reply delay (idle bits between the request's end and the reply's start) of the last reply.
  std::int64_t last_gap() const { return rec.gap_bits(rec.size() - 1); }

  fdl::BusParams params = fdl::BusParams::defaults(bus::Baud::k1_5M);
  bus::Scheduler sched;
  bus::Line line{sched, "dp", bus::Baud::k1_5M};
  FrameRecorder rec;
  ScriptMaster master;
  SlaveEngine engine;
  fdl::PassiveStation station;
  bus::Ticks m_t = 0;
};

TEST_F(SlaveOnLine, StartupAndDataExchangeGoldenFrames) {
  engine.application().write_inputs(0, Bytes{0x3C});
  // Slave_Diag (first frame, FCB=1 FCV=0) -> SD3 reply with the unparameterised diagnosis.
  EXPECT_EQ(exchange("68 05 05 68 8A 81 6D 3C 3E F2 16"), "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
  EXPECT_EQ(last_gap(), 11);  // min TSDR 11 at 1.5 Mbit/s
  // Set_Prm (FCB=0 FCV=1): SC.
  EXPECT_EQ(exchange("68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16"), "E5");
  EXPECT_EQ(station.min_tsdr(), 11u);
  // Chk_Cfg 10 20 (FCB=1): SC.
  EXPECT_EQ(exchange("68 07 07 68 8A 81 7D 3E 3E 10 20 34 16"), "E5");
  // Slave_Diag (FCB=0): 00 0C 00 01 12 34; FCS 8A+81+5D+3C+3E = E2, reply FCS E0.
  EXPECT_EQ(exchange("68 05 05 68 8A 81 5D 3C 3E E2 16"), "A2 81 8A 08 3E 3C 00 0C 00 01 12 34 E0 16");
  // Data_Exchange (FCB=1), output 42: FCS 0A+01+7D+42 = CA; the Appendix 1 reply with input 3C.
  EXPECT_EQ(exchange("68 04 04 68 0A 01 7D 42 CA 16"), "68 04 04 68 01 0A 08 3C 4F 16");
  Bytes out(1);
  engine.application().read_outputs(1, out);
  EXPECT_EQ(out, Bytes{0x42});
  // A new diagnosis: the next Data_Exchange (FCB=0, output 43: FCS AB) answers DH (FC 0A):
  // FCS 01+0A+0A+3C = 51.
  engine.application().set_ext_diag(true);
  EXPECT_EQ(exchange("68 04 04 68 0A 01 5D 43 AB 16"), "68 04 04 68 01 0A 0A 3C 51 16");
  // Global_Control Clear, broadcast (Appendix 1): no reply; outputs safe.
  EXPECT_EQ(exchange("68 07 07 68 FF 81 46 3A 3E 02 00 40 16"), "");
  engine.application().read_outputs(1, out);
  EXPECT_EQ(out, Bytes{0x00});
}

TEST_F(SlaveOnLine, WatchdogExpiresWithoutTraffic) {
  EXPECT_EQ(exchange("68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16"), "E5");
  EXPECT_EQ(exchange("68 07 07 68 8A 81 7D 3E 3E 10 20 34 16"), "E5");
  EXPECT_EQ(engine.state(), SlaveState::DataExch);
  // Watchdog 1 s; nothing arrives. The station's timer drives SlaveEngine::on_time().
  sched.run_until(sched.now() + bus::kTicksPerSecond);
  EXPECT_EQ(engine.state(), SlaveState::WaitPrm);
  // Data_Exchange now gets RS: SD1 reply, FC 03, FCS 01+0A+03 = 0E.
  EXPECT_EQ(exchange("68 04 04 68 0A 01 5D 42 AA 16"), "10 01 0A 03 0E 16");
  // Diagnosis back to Prm_Req (FCB=1: 8A+81+7D+3C+3E = 102 -> 02).
  EXPECT_EQ(exchange("68 05 05 68 8A 81 7D 3C 3E 02 16"), "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
}

class SlaveOnLineAt126 : public SlaveOnLine {
 protected:
  SlaveOnLineAt126() : SlaveOnLine(126) {}
};

TEST_F(SlaveOnLineAt126, SetSlaveAddGoldenFrame) {
  // Appendix 1: Set_Slave_Add 126 -> 5, ident 0x1234: SC, then the station answers at 5.
  EXPECT_EQ(exchange("68 09 09 68 FE 81 6D 37 3E 05 12 34 00 AC 16"), "E5");
  EXPECT_EQ(station.address(), 5);
  // Slave_Diag to 5 (first frame): 85+81+6D+3C+3E = 1ED -> ED; reply 81+85+08+3E+3C+02+05+00+FF+
  // 12+34 = 2D4 -> D4.
  EXPECT_EQ(exchange("68 05 05 68 85 81 6D 3C 3E ED 16"), "A2 81 85 08 3E 3C 02 05 00 FF 12 34 D4 16");
  // Nobody answers at 126 any more.
  EXPECT_EQ(exchange("68 05 05 68 FE 81 6D 3C 3E 66 16"), "");
}

}  // namespace
}  // namespace pbvbus::dp
