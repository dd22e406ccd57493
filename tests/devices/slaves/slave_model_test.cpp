// SlaveModel (devices/slave_model.hpp): DP slaves built from the shipped GSD files and a module
// list, brought up by a class-1 dp::Master on a real line at 1.5 Mbit/s. The frames on the wire
// are asserted byte by byte against hand-written SD2/SD3 telegrams (protocol-facts.md Appendix 1
// layouts; User_Prm_Data assembled by hand from the GSD's ExtUserPrmData defaults); I/O
// behaviours against their formulas at the virtual time of the request; faults against the
// diagnosis block layouts of §D.5/§E.5.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::devices {
namespace {

using pbvbus::test::FrameRecorder;
using Bytes = std::vector<std::uint8_t>;

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kMs = bus::kTicksPerMs;

std::string gsd_path(const char* name) { return std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name; }

GsdFile load(const char* name) {
  auto r = load_gsd(gsd_path(name));
  EXPECT_TRUE(r.ok()) << name;
  return *r.file;
}

std::string read_text(const char* name) {
  std::ifstream f(gsd_path(name), std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// Frames of the message cycles between master 1 and `slave` (requests other than FDL Status and
/// the replies that follow them), in order, as hex; `index` gets their recorder indices.
std::vector<std::string> dialogue(const FrameRecorder& rec, std::uint8_t slave,
                                  std::vector<std::size_t>* index = nullptr) {
  std::vector<std::string> out;
  bool ours = false;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    fdl::Telegram t;
    if (fdl::decode(rec.frame(i).bytes, t) != fdl::DecodeError::None) {
      ours = false;
      continue;
    }
    bool take = false;
    if (t.type == fdl::FrameType::SD4) {
      ours = false;
    } else if (t.is_request()) {
      ours = t.da == slave && t.sa == 1 && fdl::fc_request_fn(t.fc) != fdl::RequestFn::FdlStatus;
      take = ours;
    } else {
      take = ours;
      ours = false;
    }
    if (take) {
      out.push_back(rec.hex(i));
      if (index) index->push_back(i);
    }
  }
  return out;
}

bool on_wire(const FrameRecorder& rec, const std::string& hex) {
  for (std::size_t i = 0; i < rec.size(); ++i)
    if (rec.hex(i) == hex) return true;
  return false;
}

/// A Slave_Diag request from master 1 to `slave` (any FCB).
bool is_diag_request(const FrameRecorder::Frame& f, std::uint8_t slave) {
  fdl::Telegram t;
  return fdl::decode(f.bytes, t) == fdl::DecodeError::None && t.is_request() && t.da == slave &&
         t.sa == 1 && t.dsap == 0x3C && t.ssap == 0x3E && t.data.empty();
}

struct Bench {
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  FrameRecorder rec;
  fdl::BusParams bp;
  std::unique_ptr<dp::Master> master;
  std::unique_ptr<fdl::ActiveStation> station;
  std::unique_ptr<SlaveModel> model;
  bus::AttachmentId slave_att = -1;
  std::vector<dp::MasterEvent> events;

  Bench(const GsdFile& gsd, const std::vector<ModuleChoice>& mods, std::uint8_t address,
        std::optional<std::uint32_t> tsdr = std::nullopt, std::vector<GsdPrmSetting> settings = {}) {
    bp = fdl::BusParams::defaults(kBaud);
    bp.hsa = 12;
    line.add_tap(rec);
    auto sp = master_slave_params(gsd, mods, address, settings);
    EXPECT_TRUE(sp.ok());
    master = std::make_unique<dp::Master>(dp::MasterParams{}, std::vector<dp::SlaveParams>{*sp.value});
    master->set_event_handler([this](const dp::MasterEvent& e) { events.push_back(e); });
    station = std::make_unique<fdl::ActiveStation>(1, bp, *master);
    line.attach(*station, "master 1");
    SlaveModelOptions o;
    o.address = address;
    o.bus_params = bp;
    o.tsdr = tsdr;
    auto b = SlaveModel::build(gsd, mods, o);
    EXPECT_TRUE(b.ok()) << (b.errors.empty() ? "" : b.errors[0]);
    model = std::move(b.model);
    slave_att = line.attach(*model, model->name());
  }
  void start() { line.start(); }
  void run_for(bus::Ticks t) { sched.run_until(sched.now() + t); }
  void run_until(bus::Ticks t) { sched.run_until(t); }
  /// Data bytes (after FC) of a DX response frame.
  static Bytes dx_inputs(const FrameRecorder::Frame& f) {
    fdl::Telegram t;
    EXPECT_EQ(fdl::decode(f.bytes, t), fdl::DecodeError::None);
    return Bytes(t.data.begin(), t.data.end());
  }
};

// --- PBVB0A01: compact station, counter per DP cycle, own TSDR ---------------------------------

TEST(SlaveModelLine, CompactStationStartupAndCounterPerCycle) {
  const GsdFile gsd = load("PBVB0A01.gsd");
  Bench b(gsd, {ModuleChoice::named("16DI/16DO DC24V")}, 5, 30);
  ASSERT_EQ(b.model->set_behaviour(0, IoBehaviour::counter_per_cycle(1, 0x1234)), "");
  EXPECT_EQ(b.model->config().ident, 0x0A01);
  EXPECT_TRUE(b.model->config().features.sync);
  EXPECT_TRUE(b.model->config().features.freeze);
  EXPECT_TRUE(b.model->config().features.fail_safe);
  EXPECT_TRUE(b.model->config().features.set_slave_add);
  EXPECT_FALSE(b.model->config().features.dpv1);
  EXPECT_EQ(b.model->config().max_diag_len, 8u);
  b.start();
  b.run_for(20 * kMs);
  ASSERT_EQ(b.master->slave_state(5), dp::SlaveStatusState::DataExchange);

  std::vector<std::size_t> idx;
  const auto d = dialogue(b.rec, 5, &idx);
  ASSERT_GE(d.size(), 14u);
  EXPECT_EQ(d[0], "68 05 05 68 85 81 6D 3C 3E ED 16");
  EXPECT_EQ(d[1], "A2 81 85 08 3E 3C 02 05 00 FF 0A 01 99 16");  // Not_Ready, Prm_Req
  // Set_Prm: Lock + WD_On, WD 10×10, min TSDR 11, ident 0A01, group 0, User_Prm_Data 0x12
  // (Bit(1) = 1 load voltage diagnosis, BitArea(4-5) = 1 input delay 3 ms, Bit(0) = 0).
  EXPECT_EQ(d[2], "68 0D 0D 68 85 81 5D 3D 3E 88 0A 0A 0B 0A 01 00 12 A2 16");
  EXPECT_EQ(d[3], "E5");
  EXPECT_EQ(d[4], "68 07 07 68 85 81 7D 3E 3E 11 21 31 16");  // Chk_Cfg 11 21
  EXPECT_EQ(d[5], "E5");
  EXPECT_EQ(d[6], "68 05 05 68 85 81 5D 3C 3E DD 16");
  EXPECT_EQ(d[7], "A2 81 85 08 3E 3C 00 0C 00 01 0A 01 A0 16");  // WD_On, master 1
  // Data_Exchange: two output octets 00 00; inputs = the counter, 0x1234 then 0x1235.
  EXPECT_EQ(d[8], "68 05 05 68 05 01 7D 00 00 83 16");
  EXPECT_EQ(d[9], "68 05 05 68 01 05 08 12 34 54 16");
  EXPECT_EQ(d[10], "68 05 05 68 05 01 5D 00 00 63 16");
  EXPECT_EQ(d[11], "68 05 05 68 01 05 08 12 35 55 16");
  // Every reply starts exactly TSDR = 30 t_bit after its request (the configured station delay).
  for (std::size_t k = 1; k < 12; k += 2) EXPECT_EQ(b.rec.gap_bits(idx[k]), 30) << k;
  // The n-th Data_Exchange answer carries 0x1234 + n.
  std::uint64_t n = 0;
  for (std::size_t k = 8; k + 1 < d.size(); k += 2, ++n) {
    const Bytes in = Bench::dx_inputs(b.rec.frame(idx[k + 1]));
    ASSERT_EQ(in.size(), 2u);
    EXPECT_EQ((in[0] << 8) | in[1], static_cast<int>(0x1234 + n)) << k;
  }
  EXPECT_EQ(b.model->dp_cycles(), n);
}

// --- PBVB0A02: modular station, constant / ramp / table / echo, channel diag, pulled module ----

std::vector<ModuleChoice> ms8_modules() {
  return {ModuleChoice::named("8DI DC24V"), ModuleChoice::named("16DO DC24V/0.5A"),
          ModuleChoice::named("4AI U/I 16 bit"), ModuleChoice::parse("#5"),  // 2AO by index
          ModuleChoice::named("16DI DC24V")};
}

TEST(SlaveModelLine, ModularStationStartupAndBehaviours) {
  const GsdFile gsd = load("PBVB0A02.gsd");
  Bench b(gsd, ms8_modules(), 6);
  auto& m = *b.model;
  ASSERT_EQ(m.set_behaviour(0, IoBehaviour::constant_value({0xA5})), "");
  ASSERT_EQ(m.add_channel_behaviour(2, 0, 2, IoBehaviour::ramp(0, 27648, 10 * kMs)), "");
  ASSERT_EQ(m.add_channel_behaviour(2, 2, 2, IoBehaviour::table({{0, 100}, {5 * kMs, -200}}, true, 10 * kMs)), "");
  ASSERT_EQ(m.set_behaviour(4, IoBehaviour::echo(1)), "");
  EXPECT_EQ(m.config().min_slave_interval, 2);
  EXPECT_EQ(m.config().max_diag_len, 32u);
  EXPECT_EQ(m.config().min_user_prm_len, 12u);
  b.start();
  b.run_for(20 * kMs);
  ASSERT_EQ(b.master->slave_state(6), dp::SlaveStatusState::DataExchange);

  std::vector<std::size_t> idx;
  auto d = dialogue(b.rec, 6, &idx);
  ASSERT_GE(d.size(), 10u);
  EXPECT_EQ(d[0], "68 05 05 68 86 81 6D 3C 3E EE 16");
  EXPECT_EQ(d[1], "A2 81 86 08 3E 3C 02 05 00 FF 0A 02 9B 16");
  // User_Prm_Data: station 01 | 8DI 01 | 16DO 00 | 4AI 02 02 02 02 00 64 | 2AO 02 02 | 16DI 01.
  EXPECT_EQ(d[2], "68 18 18 68 86 81 5D 3D 3E 88 0A 0A 0B 0A 02 00 01 01 00 02 02 02 02 00 64 02 02 01 05 16");
  EXPECT_EQ(d[3], "E5");
  EXPECT_EQ(d[4], "68 0A 0A 68 86 81 7D 3E 3E 10 21 D3 61 11 76 16");
  EXPECT_EQ(d[5], "E5");
  EXPECT_EQ(d[6], "68 05 05 68 86 81 5D 3C 3E DE 16");
  EXPECT_EQ(d[7], "A2 81 86 08 3E 3C 00 0C 00 01 0A 02 A2 16");
  // Data_Exchange: 6 output octets out, 11 input octets back.
  EXPECT_EQ(d[8], "68 09 09 68 06 01 7D 00 00 00 00 00 00 84 16");

  // Echo: the master's 16DO outputs come back as the 16DI inputs.
  const Bytes out{0xBE, 0xEF};
  ASSERT_EQ(b.master->image(6).write_outputs(1, out), dp::ImageAccess::Ok);
  b.run_for(5 * kMs);
  Bytes got(2);
  ASSERT_EQ(b.master->image(6).read_inputs(4, got), dp::ImageAccess::Ok);
  EXPECT_EQ(got, out);

  idx.clear();
  d = dialogue(b.rec, 6, &idx);
  int checked = 0;
  for (std::size_t k = 8; k + 1 < d.size(); k += 2) {
    const Bytes in = Bench::dx_inputs(b.rec.frame(idx[k + 1]));
    ASSERT_EQ(in.size(), 11u);
    const bus::Ticks t = b.rec.frame(idx[k]).end;  // the slave computes at the request's end
    EXPECT_EQ(in[0], 0xA5);
    const std::int64_t ramp = 27648 * (t % (10 * kMs)) / (10 * kMs);
    EXPECT_EQ((in[1] << 8) | in[2], ramp) << "t=" << t;
    const int table = (t % (10 * kMs)) < 5 * kMs ? 100 : (-200 & 0xFFFF);
    EXPECT_EQ((in[3] << 8) | in[4], table) << "t=" << t;
    EXPECT_EQ(in[5], 0);  // channels 2, 3 without behaviour
    EXPECT_EQ(in[8], 0);
    ++checked;
  }
  EXPECT_GT(checked, 20);
  // The last answers show the echo (inputs octets 9, 10 = module 4).
  const Bytes last = Bench::dx_inputs(b.rec.frame(idx.back()));
  EXPECT_EQ(last[9], 0xBE);
  EXPECT_EQ(last[10], 0xEF);
}

TEST(SlaveModelLine, ChannelDiagnosisGivesDhThenTheChannelBlock) {
  const GsdFile gsd = load("PBVB0A02.gsd");
  Bench b(gsd, ms8_modules(), 6);
  // Short circuit on channel 3 of the 4AI (module 2, identifier 2), word input channel.
  ASSERT_EQ(b.model->schedule(15 * kMs, SlaveFault::channel_diag(2, 3, dp::ChannelError::ShortCircuit,
                                                                  dp::ChannelType::Word)),
            "");
  ASSERT_EQ(b.model->schedule(25 * kMs, SlaveFault::channel_diag(2, 3, dp::ChannelError::ShortCircuit,
                                                                  dp::ChannelType::Word,
                                                                  dp::ChannelDirection::Input, false)),
            "");
  b.start();
  b.run_until(15 * kMs);
  ASSERT_EQ(b.master->slave_state(6), dp::SlaveStatusState::DataExchange);
  const std::size_t before = b.rec.size();
  b.run_until(20 * kMs);
  // The first Data_Exchange after 15 ms is answered DH (FC 0A), then the master reads the diag:
  // Ext_Diag, and the channel block 82 43 A1 (identifier 2; input, channel 3; word, short circuit).
  std::vector<std::size_t> idx;
  const auto d = dialogue(b.rec, 6, &idx);
  std::size_t k = 0;
  while (k < idx.size() && idx[k] < before) ++k;
  ASSERT_LT(k + 3, d.size());
  ASSERT_EQ(d[k].substr(0, 18), "68 09 09 68 06 01 ");  // a Data_Exchange request
  EXPECT_EQ(d[k + 1].substr(0, 21), "68 0E 0E 68 01 06 0A ");  // 11 inputs, FC DH
  EXPECT_TRUE(is_diag_request(b.rec.frame(idx[k + 2]), 6));
  EXPECT_EQ(d[k + 3], "68 0E 0E 68 81 86 08 3E 3C 08 0C 00 01 0A 02 82 43 A1 10 16");
  EXPECT_EQ(b.master->slave_state(6), dp::SlaveStatusState::DataExchange);
  // Gone at 25 ms: DH again, then the plain diagnosis.
  b.run_until(30 * kMs);
  EXPECT_EQ(pbvbus::test::to_hex(b.master->slave_diag(6)), "00 0C 00 01 0A 02");
  EXPECT_FALSE(b.rec.frames().empty());
}

TEST(SlaveModelLine, PulledModuleShowsInTheIdentifierBlock) {
  const GsdFile gsd = load("PBVB0A02.gsd");
  Bench b(gsd, ms8_modules(), 6);
  ASSERT_EQ(b.model->set_behaviour(0, IoBehaviour::constant_value({0x5A})), "");
  ASSERT_EQ(b.model->schedule(15 * kMs, SlaveFault::pulled(0)), "");
  ASSERT_EQ(b.model->schedule(25 * kMs, SlaveFault::plugged(0)), "");
  b.start();
  b.run_until(14 * kMs);
  ASSERT_EQ(b.master->slave_state(6), dp::SlaveStatusState::DataExchange);
  Bytes in(1);
  ASSERT_EQ(b.master->image(6).read_inputs(0, in), dp::ImageAccess::Ok);
  EXPECT_EQ(in[0], 0x5A);
  b.run_until(20 * kMs);
  EXPECT_TRUE(b.model->module_pulled(0));
  // Ext_Diag; identifier-related block 42 01: one octet for five modules, bit 0 = module 0.
  EXPECT_TRUE(on_wire(b.rec, "68 0D 0D 68 81 86 08 3E 3C 08 0C 00 01 0A 02 42 01 ED 16"));
  EXPECT_EQ(pbvbus::test::to_hex(b.master->slave_diag(6)), "08 0C 00 01 0A 02 42 01");
  ASSERT_EQ(b.master->image(6).read_inputs(0, in), dp::ImageAccess::Ok);
  EXPECT_EQ(in[0], 0x00);  // a pulled module's inputs read zero
  b.run_until(30 * kMs);
  EXPECT_FALSE(b.model->module_pulled(0));
  EXPECT_EQ(pbvbus::test::to_hex(b.master->slave_diag(6)), "00 0C 00 01 0A 02");
  ASSERT_EQ(b.master->image(6).read_inputs(0, in), dp::ImageAccess::Ok);
  EXPECT_EQ(in[0], 0x5A);
  EXPECT_EQ(b.master->slave_stats(6).failures, 0u);
}

// --- PBVB0A03: DP-V1 station, time counter, pull/plug and process alarms -----------------------

std::vector<ModuleChoice> dv4_modules() {
  return {ModuleChoice::named("8DI with process alarm"), ModuleChoice::named("8DO DC24V/0.5A"),
          ModuleChoice::named("2AI U/I consistent"), ModuleChoice::named("4AI U/I special format")};
}

TEST(SlaveModelLine, Dpv1StationStartupAndCounterEveryMillisecond) {
  const GsdFile gsd = load("PBVB0A03.gsd");
  Bench b(gsd, dv4_modules(), 7);
  const auto& f = b.model->config().features;
  EXPECT_TRUE(f.dpv1);
  EXPECT_TRUE(f.c1_read_write);
  EXPECT_TRUE(f.c2);
  EXPECT_EQ(f.c2_connections, 2);
  EXPECT_EQ(f.alarms_supported, dp::kEnableDiagnosticAlarm | dp::kEnableProcessAlarm | dp::kEnablePullPlugAlarm);
  EXPECT_EQ(f.max_alarm_mode, 3);  // Alarm_Sequence_Mode_Count = 8
  EXPECT_TRUE(f.wd_base_1ms);
  // 2AI, word 1 (octets 2, 3): counter +3 every millisecond.
  ASSERT_EQ(b.model->add_channel_behaviour(2, 2, 2, IoBehaviour::counter_every(kMs, 3, 0xFFF0)), "");
  b.start();
  b.run_for(20 * kMs);
  ASSERT_EQ(b.master->slave_state(7), dp::SlaveStatusState::DataExchange);
  std::vector<std::size_t> idx;
  const auto d = dialogue(b.rec, 7, &idx);
  ASSERT_GE(d.size(), 12u);
  EXPECT_EQ(d[0], "68 05 05 68 87 81 6D 3C 3E EF 16");
  EXPECT_EQ(d[1], "A2 81 87 08 3E 3C 02 05 00 FF 0A 03 9D 16");
  // User_Prm_Data: DPV1_Status 80 E0 00 (alarms enabled by the Ext_User_Prm_Data_Ref bits),
  // station byte 01 | 8DI 01 | 2AI 03 6C 00 (range 4..20 mA, upper limit 27648).
  EXPECT_EQ(d[2], "68 14 14 68 87 81 5D 3D 3E 88 0A 0A 0B 0A 03 00 80 E0 00 01 01 03 6C 00 65 16");
  EXPECT_EQ(d[3], "E5");
  EXPECT_EQ(d[4], "68 0A 0A 68 87 81 7D 3E 3E 10 20 D1 40 C3 05 16");
  EXPECT_EQ(d[5], "E5");
  EXPECT_EQ(d[6], "68 05 05 68 87 81 5D 3C 3E DF 16");
  EXPECT_EQ(d[7], "A2 81 87 08 3E 3C 00 0C 00 01 0A 03 A4 16");
  int checked = 0;
  for (std::size_t k = 8; k + 1 < d.size(); k += 2) {
    const Bytes in = Bench::dx_inputs(b.rec.frame(idx[k + 1]));
    ASSERT_EQ(in.size(), 13u);
    const bus::Ticks t = b.rec.frame(idx[k]).end;
    const unsigned expect = (0xFFF0u + 3u * static_cast<unsigned>(t / kMs)) & 0xFFFFu;  // wraps
    EXPECT_EQ(static_cast<unsigned>((in[3] << 8) | in[4]), expect) << "t=" << t;
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

TEST(SlaveModelLine, Dpv1PullAndPlugAlarmsAndModuleStatus) {
  const GsdFile gsd = load("PBVB0A03.gsd");
  Bench b(gsd, dv4_modules(), 7);
  ASSERT_EQ(b.model->schedule(15 * kMs, SlaveFault::pulled(1)), "");
  ASSERT_EQ(b.model->schedule(25 * kMs, SlaveFault::plugged(1)), "");
  b.start();
  b.run_until(30 * kMs);
  // Pulled: Ext_Diag; identifier block 42 02 (module 1); Module_Status 05 82 00 00 0C (module 1 =
  // 11 no module); Pull alarm 04 03 02 01 (type 3, slot 2, Seq_Nr 0, appears).
  EXPECT_TRUE(on_wire(b.rec, "68 16 16 68 81 87 08 3E 3C 08 0C 00 01 0A 03 42 02 05 82 00 00 0C 04 03 02 01 8D 16"));
  // Plugged: Plug alarm 04 04 02 0A (type 4, slot 2, Seq_Nr 1, disappears); no Ext_Diag.
  EXPECT_TRUE(on_wire(b.rec, "68 0F 0F 68 81 87 08 3E 3C 00 0C 00 01 0A 03 04 04 02 0A B8 16"));
  EXPECT_EQ(b.master->slave_stats(7).alarms, 2u);
  EXPECT_EQ(b.master->slave_stats(7).alarm_acks, 2u);
  EXPECT_EQ(b.model->application().alarms_outstanding(), 0u);
  EXPECT_EQ(pbvbus::test::to_hex(b.model->engine().current_diag()), "00 0C 00 01 0A 03");
  EXPECT_EQ(b.master->slave_state(7), dp::SlaveStatusState::DataExchange);
}

TEST(SlaveModelLine, Dpv1ProcessAlarm) {
  const GsdFile gsd = load("PBVB0A03.gsd");
  Bench b(gsd, dv4_modules(), 7);
  ASSERT_EQ(b.model->schedule(15 * kMs, SlaveFault::process_alarm(0, {0x12, 0x34})), "");
  b.start();
  b.run_until(25 * kMs);
  // Process alarm 06 02 01 00 12 34 (type 2, slot 1, Seq_Nr 0) and its acknowledgement.
  EXPECT_TRUE(on_wire(b.rec, "68 11 11 68 81 87 08 3E 3C 00 0C 00 01 0A 03 06 02 01 00 12 34 F3 16"));
  bool ack = false;
  for (std::size_t i = 0; i < b.rec.size(); ++i) {
    fdl::Telegram t;
    if (fdl::decode(b.rec.frame(i).bytes, t) != fdl::DecodeError::None || !t.is_request()) continue;
    ack = ack || (t.da == 7 && t.dsap == 50 && t.ssap == 51 &&
                  pbvbus::test::to_hex(t.data) == "5C 01 02 00");
  }
  EXPECT_TRUE(ack);
  EXPECT_EQ(b.model->application().alarms_outstanding(), 0u);
}

TEST(SlaveModelLine, Dpv1ChannelDiagnosisWithDiagnosticAlarm) {
  const GsdFile gsd = load("PBVB0A03.gsd");
  Bench b(gsd, dv4_modules(), 7);
  // Wire break on channel 1 of the 2AI (module 2, identifier 2, slot 3), word input.
  SlaveFault f = SlaveFault::channel_diag(2, 1, dp::ChannelError::LineBreak, dp::ChannelType::Word);
  f.alarm = true;
  ASSERT_EQ(b.model->schedule(15 * kMs, f), "");
  b.start();
  b.run_until(25 * kMs);
  // Ext_Diag; channel block 82 41 A6; Diagnostic alarm 07 01 03 01 (type 1, slot 3, Seq_Nr 0,
  // appears) carrying the channel octets.
  EXPECT_TRUE(on_wire(b.rec, "68 15 15 68 81 87 08 3E 3C 08 0C 00 01 0A 03 82 41 A6 07 01 03 01 82 41 A6 8A 16"));
  EXPECT_EQ(b.master->slave_stats(7).alarm_acks, 1u);
  // Acknowledged: the alarm leaves the diagnosis, the channel diagnosis stays.
  EXPECT_EQ(pbvbus::test::to_hex(b.model->engine().current_diag()), "08 0C 00 01 0A 03 82 41 A6");
  EXPECT_EQ(b.master->slave_state(7), dp::SlaveStatusState::DataExchange);
}

// --- F3: module parameter data records (module_records.hpp) -------------------------------------

TEST(SlaveModelLine, Dpv1ModuleParameterRecordWrittenReadAndForgottenWhenPulled) {
  const GsdFile gsd = load("PBVB0A03.gsd");  // DPV1_Slave, C1_Read_Write_supp
  Bench b(gsd, dv4_modules(), 7);
  ASSERT_NE(b.model->module_records(), nullptr);
  std::vector<dp::AcyclicResult> res;
  auto keep = [&](const dp::AcyclicResult& r) { res.push_back(r); };
  b.start();
  b.run_until(20 * kMs);
  ASSERT_EQ(b.master->slave_state(7), dp::SlaveStatusState::DataExchange);
  const Bytes rec{0x12, 0x34};
  // Write record 1 of the 8DO (module 1 = slot 2): accepted. Response (SD2, DSAP = SSAP = 51 =
  // 0x33, FC 08 DL) `5F 02 01 02`; FCS = 81+87+08+33+33+5F+02+01+02 = 0x1DA -> DA.
  ASSERT_NE(b.master->write(7, 2, 1, rec, keep), 0u);
  b.run_for(5 * kMs);
  ASSERT_EQ(res.size(), 1u);
  EXPECT_EQ(res[0].status, dp::AcyclicStatus::Ok);
  EXPECT_TRUE(on_wire(b.rec, "68 09 09 68 81 87 08 33 33 5F 02 01 02 DA 16"));
  EXPECT_EQ(b.model->module_records()->record(1, 1), rec);
  EXPECT_EQ(b.model->module_records()->writes_accepted(), 1u);
  // Read it back: `5E 02 01 02 12 34`; DSAP, SSAP and six DU octets are exactly the eight data
  // octets of an SD3 frame. FCS = 0x176+5E+02+01+02+12+34 = 0x21F -> 1F.
  ASSERT_NE(b.master->read(7, 2, 1, 240, keep), 0u);
  b.run_for(5 * kMs);
  ASSERT_EQ(res.size(), 2u);
  EXPECT_EQ(res[1].status, dp::AcyclicStatus::Ok);
  EXPECT_EQ(res[1].data, rec);
  EXPECT_TRUE(on_wire(b.rec, "A2 81 87 08 33 33 5E 02 01 02 12 34 1F 16"));
  // A record never written: invalid index `DE 80 B0 00`.
  ASSERT_NE(b.master->read(7, 2, 2, 4, keep), 0u);
  b.run_for(5 * kMs);
  ASSERT_EQ(res.size(), 3u);
  EXPECT_EQ(res[2].status, dp::AcyclicStatus::Negative);
  EXPECT_EQ(res[2].error.code_1, 0xB0);
  // Slot 5 (4 modules): invalid slot `DF 80 B2 00`; LE = 5 + 4 = 9; FCS = 0x176+DF+80+B2+00 =
  // 0x387 -> 87.
  ASSERT_NE(b.master->write(7, 5, 1, rec, keep), 0u);
  b.run_for(5 * kMs);
  ASSERT_EQ(res.size(), 4u);
  EXPECT_EQ(res[3].status, dp::AcyclicStatus::Negative);
  EXPECT_EQ(res[3].error.code_1, 0xB2);
  EXPECT_TRUE(on_wire(b.rec, "68 09 09 68 81 87 08 33 33 DF 80 B2 00 87 16"));
  // Pulled: the record is gone and a write to the empty slot is "invalid slot".
  ASSERT_EQ(b.model->apply(SlaveFault::pulled(1)), "");
  EXPECT_EQ(b.model->module_records()->record(1, 1), std::nullopt);
  ASSERT_NE(b.master->write(7, 2, 1, rec, keep), 0u);
  b.run_for(5 * kMs);
  ASSERT_EQ(res.size(), 5u);
  EXPECT_EQ(res[4].status, dp::AcyclicStatus::Negative);
  EXPECT_EQ(res[4].error.code_1, 0xB2);
  // Plugged: a new module without parameters (read: invalid index) until the record is written.
  ASSERT_EQ(b.model->apply(SlaveFault::plugged(1)), "");
  b.run_for(5 * kMs);
  ASSERT_NE(b.master->read(7, 2, 1, 240, keep), 0u);
  b.run_for(5 * kMs);
  ASSERT_EQ(res.size(), 6u);
  EXPECT_EQ(res[5].error.code_1, 0xB0);
  ASSERT_NE(b.master->write(7, 2, 1, Bytes{0x56}, keep), 0u);
  b.run_for(5 * kMs);
  ASSERT_EQ(res.size(), 7u);
  EXPECT_EQ(res[6].status, dp::AcyclicStatus::Ok);
  EXPECT_EQ(b.model->module_records()->record(1, 1), Bytes{0x56});
  EXPECT_EQ(b.model->module_records()->writes_accepted(), 2u);
  // A DP-V0 station has no records (no MSAC_C1).
  const GsdFile v0 = load("PBVB0A02.gsd");
  Bench c(v0, {ModuleChoice::named("8DI DC24V")}, 8);
  EXPECT_EQ(c.model->module_records(), nullptr);
}

// --- mute ---------------------------------------------------------------------------------------

TEST(SlaveModelLine, MutedSlaveIsSilentThenReturns) {
  const GsdFile gsd = load("PBVB0A01.gsd");
  Bench b(gsd, {ModuleChoice::at(0)}, 5);
  ASSERT_EQ(b.model->schedule(15 * kMs, SlaveFault::mute()), "");
  ASSERT_EQ(b.model->schedule(40 * kMs, SlaveFault::unmute()), "");
  b.start();
  b.run_until(15 * kMs);
  ASSERT_EQ(b.master->slave_state(5), dp::SlaveStatusState::DataExchange);
  const std::size_t from = b.rec.size();
  const std::uint64_t heard = b.model->station().stats().requests;
  const std::uint64_t cycles = b.model->dp_cycles();
  b.run_until(40 * kMs - 1);
  EXPECT_TRUE(b.model->muted());
  // Deaf: nothing reached the passive station or the engine while muted.
  EXPECT_EQ(b.model->station().stats().requests, heard);
  EXPECT_EQ(b.model->dp_cycles(), cycles);
  int requests = 0;
  for (std::size_t i = from; i < b.rec.size(); ++i) {
    fdl::Telegram t;
    if (fdl::decode(b.rec.frame(i).bytes, t) != fdl::DecodeError::None) continue;
    if (t.type == fdl::FrameType::SC) continue;
    if (t.is_request() && t.da == 5) ++requests;
    EXPECT_FALSE(!t.is_request() && t.sa == 5) << "reply from the muted slave: " << b.rec.hex(i);
  }
  EXPECT_GT(requests, 2);  // the master kept asking
  EXPECT_EQ(b.master->slave_state(5), dp::SlaveStatusState::NotPresent);
  // Its watchdog (10 × 10 × 10 ms = 1 s) has not expired yet; after unmute the master restarts it.
  b.run_until(60 * kMs);
  EXPECT_FALSE(b.model->muted());
  EXPECT_EQ(b.master->slave_state(5), dp::SlaveStatusState::DataExchange);
  EXPECT_EQ(b.master->slave_stats(5).failures, 1u);
  EXPECT_EQ(b.master->slave_stats(5).returns, 1u);
}

// --- User_Prm_Data content check ------------------------------------------------------------------

TEST(SlaveModelLine, ParameterOutsideTheGsdRangeIsAPrmFault) {
  const GsdFile gsd = load("PBVB0A02.gsd");
  SlaveModelOptions o;
  o.address = 6;
  o.bus_params = fdl::BusParams::defaults(kBaud);
  auto r = SlaveModel::build(gsd, ms8_modules(), o);
  ASSERT_TRUE(r.ok());
  auto& e = r.model->engine();
  e.on_power_on(0);
  auto set_prm = [&](Bytes user) {
    Bytes du{0x88, 0x0A, 0x0A, 0x0B, 0x0A, 0x02, 0x00};
    du.insert(du.end(), user.begin(), user.end());
    fdl::Indication ind;
    ind.sa = 1;
    ind.da = 6;
    ind.dsap = 61;
    ind.ssap = 62;
    ind.data = du;
    fdl::Reply rep;
    e.on_request(ind, rep);
    return pbvbus::test::to_hex(e.current_diag());
  };
  const Bytes good = pbvbus::test::bytes_from_hex("01 01 00 02 02 02 02 00 64 02 02 01");
  EXPECT_EQ(r.model->default_user_prm(), good);
  EXPECT_EQ(set_prm(good), "02 0C 00 01 0A 02");  // accepted: Wait_Cfg, locked by master 1
  // Measuring range (Unsigned8 0..4) of 4AI channel 2 = 9: Prm_Fault, back to Wait_Prm.
  EXPECT_EQ(set_prm(pbvbus::test::bytes_from_hex("01 01 00 02 02 09 02 00 64 02 02 01")), "42 05 00 FF 0A 02");
  // Smoothing time (Unsigned16 0..1000) = 1001.
  EXPECT_EQ(set_prm(pbvbus::test::bytes_from_hex("01 01 00 02 02 02 02 03 E9 02 02 01")), "42 05 00 FF 0A 02");
  // Output range (enumeration 1,2,3,4) = 0.
  EXPECT_EQ(set_prm(pbvbus::test::bytes_from_hex("01 01 00 02 02 02 02 00 64 00 02 01")), "42 05 00 FF 0A 02");
  // One octet short.
  EXPECT_EQ(set_prm(pbvbus::test::bytes_from_hex("01 01 00 02 02 02 02 00 64 02 02")), "42 05 00 FF 0A 02");
  EXPECT_EQ(set_prm(good), "02 0C 00 01 0A 02");
}

// --- build errors ---------------------------------------------------------------------------------

SlaveModelOptions opts(bus::Baud baud, std::optional<std::uint32_t> tsdr = std::nullopt) {
  SlaveModelOptions o;
  o.address = 9;
  o.bus_params = fdl::BusParams::defaults(baud);
  o.tsdr = tsdr;
  return o;
}

TEST(SlaveModelErrors, UnknownModuleNameAndIndex) {
  const GsdFile gsd = load("PBVB0A02.gsd");
  auto r = SlaveModel::build(gsd, {ModuleChoice::named("8DI DC24V"), ModuleChoice::named("32DI DC24V"),
                                   ModuleChoice::parse("#6")},
                             opts(kBaud));
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 2u);
  EXPECT_EQ(r.errors[0].rfind("module 1: unknown module \"32DI DC24V\" (PBVB0A02.gsd has #0 \"8DI DC24V\", ", 0), 0u)
      << r.errors[0];
  EXPECT_EQ(r.errors[1], "module 2: index #6 out of range (PBVB0A02.gsd has 6 modules)");
  EXPECT_FALSE(SlaveModel::build(gsd, {}, opts(kBaud)).ok());
}

TEST(SlaveModelErrors, TooManyModules) {
  const GsdFile gsd = load("PBVB0A02.gsd");
  std::vector<ModuleChoice> nine(9, ModuleChoice::named("8DI DC24V"));
  auto r = SlaveModel::build(gsd, nine, opts(kBaud));
  EXPECT_FALSE(r.ok());
  ASSERT_FALSE(r.errors.empty());
  EXPECT_NE(r.errors[0].find("Max_Module"), std::string::npos) << r.errors[0];
  // A compact station takes exactly its one module.
  const GsdFile cs = load("PBVB0A01.gsd");
  EXPECT_FALSE(SlaveModel::build(cs, {ModuleChoice::at(0), ModuleChoice::at(0)}, opts(kBaud)).ok());
}

TEST(SlaveModelErrors, TsdrMustLieWithinMinTsdrAndMaxTsdr) {
  const GsdFile gsd = load("PBVB0A01.gsd");
  auto r = SlaveModel::build(gsd, {ModuleChoice::at(0)}, opts(bus::Baud::k12M, 801));
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0], "TSDR 801 t_bit is above the GSD's MaxTsdr_12M = 800 t_bit");
  EXPECT_TRUE(SlaveModel::build(gsd, {ModuleChoice::at(0)}, opts(bus::Baud::k12M, 800)).ok());
  r = SlaveModel::build(gsd, {ModuleChoice::at(0)}, opts(kBaud, 10));
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0], "TSDR 10 t_bit is below the min TSDR 11 t_bit");
  auto ok = SlaveModel::build(gsd, {ModuleChoice::at(0)}, opts(kBaud));
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok.model->tsdr(), 11u);
}

TEST(SlaveModelErrors, BaudTheGsdDoesNotSupport) {
  std::string text = read_text("PBVB0A01.gsd");
  for (const char* key : {"3M_supp                 = 1\n", "MaxTsdr_3M              = 250\n"}) {
    const auto pos = text.find(key);
    ASSERT_NE(pos, std::string::npos) << key;
    text.erase(pos, std::string(key).size());
  }
  auto parsed = parse_gsd(text, "no3M.gsd");
  ASSERT_TRUE(parsed.ok());
  auto r = SlaveModel::build(*parsed.file, {ModuleChoice::at(0)}, opts(bus::Baud::k3M));
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].rfind("baud rate 3M is not supported by no3M.gsd (supported: 9.6k, ", 0), 0u) << r.errors[0];
  EXPECT_TRUE(SlaveModel::build(*parsed.file, {ModuleChoice::at(0)}, opts(bus::Baud::k6M)).ok());
}

// --- PROFIsafe module (tests/data/gsd/vendor-quirks/profisafe-module.gsd) ---------------------

TEST(SlaveModelLine, ProfisafeModuleFParametersInSetPrm) {
  auto parsed = load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/tests/data/gsd/vendor-quirks/profisafe-module.gsd");
  ASSERT_TRUE(parsed.ok());
  const GsdFile& gsd = *parsed.file;
  Bench b(gsd, {ModuleChoice::named("8DI DC24V"), ModuleChoice::named("F-DI 2x24V PROFIsafe")}, 7);
  // DPV1_Status 80 00 00, 8DI 01, F-DI 01 0A, F-parameters 08 40 00 01 00 64 00 96 4A 2B
  // (worked out in gsd_vendor_quirks_test.cpp).
  const Bytes user_prm = pbvbus::test::bytes_from_hex("80 00 00 01 01 0A 08 40 00 01 00 64 00 96 4A 2B");
  EXPECT_EQ(b.model->default_user_prm(), user_prm);
  EXPECT_EQ(b.model->config().min_user_prm_len, 16u);
  b.start();
  b.run_for(20 * kMs);
  ASSERT_EQ(b.master->slave_state(7), dp::SlaveStatusState::DataExchange);
  // The Set_Prm on the wire carries the 7 standard octets, then the whole User_Prm_Data.
  std::vector<std::size_t> idx;
  const auto d = dialogue(b.rec, 7, &idx);
  ASSERT_GE(d.size(), 3u);
  fdl::Telegram t;
  ASSERT_EQ(fdl::decode(b.rec.frame(idx[2]).bytes, t), fdl::DecodeError::None);
  EXPECT_EQ(t.dsap, 0x3D);  // Set_Prm SAP 61
  ASSERT_EQ(t.data.size(), 7u + user_prm.size());
  EXPECT_EQ(Bytes(t.data.begin() + 7, t.data.end()), user_prm);

  // The slave checks the F-parameters against their F_ExtUserPrmData ranges: F_Par_Version 0
  // (octet 7, bits 6-7) and F_Dest_Add 0 (octets 10-11) are refused.
  const auto& check = b.model->config().check_user_prm;
  ASSERT_TRUE(check);
  EXPECT_TRUE(check(user_prm));
  Bytes bad = user_prm;
  bad[7] = 0x00;
  EXPECT_FALSE(check(bad));
  bad = user_prm;
  bad[10] = 0x00;
  bad[11] = 0x00;
  EXPECT_FALSE(check(bad));
}

TEST(SlaveModelErrors, BadBehavioursAndFaults) {
  const GsdFile gsd = load("PBVB0A02.gsd");
  auto r = SlaveModel::build(gsd, ms8_modules(), opts(kBaud));
  ASSERT_TRUE(r.ok());
  auto& m = *r.model;
  EXPECT_EQ(m.set_behaviour(1, IoBehaviour::constant_value({1})), "module 1 has no inputs");
  EXPECT_EQ(m.set_behaviour(9, IoBehaviour::constant_value({1})), "module 9 does not exist");
  EXPECT_NE(m.add_channel_behaviour(2, 7, 2, IoBehaviour::constant_value({1})), "");
  EXPECT_NE(m.set_behaviour(0, IoBehaviour::echo(0)), "");  // 8DI has no outputs
  EXPECT_NE(m.set_behaviour(0, IoBehaviour::ramp(5, 1, kMs)), "");
  EXPECT_NE(m.set_behaviour(0, IoBehaviour::table({}, false)), "");
  EXPECT_NE(m.set_behaviour(0, IoBehaviour::table({{0, 1}, {5 * kMs, 2}}, true, 5 * kMs)), "");
  EXPECT_NE(m.apply(SlaveFault::pulled(5)), "");
  EXPECT_NE(m.apply(SlaveFault::process_alarm(0, {1})), "");  // not DP-V1
  EXPECT_NE(m.apply(SlaveFault::channel_diag(0, 64, dp::ChannelError::ShortCircuit)), "");
}

}  // namespace
}  // namespace pbvbus::devices
