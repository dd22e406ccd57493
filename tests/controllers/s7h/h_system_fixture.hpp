#pragma once
// The H-system test fixture shared by h_system_test.cpp, h_system_update_test.cpp and
// h_system_program_test.cpp: an HCpuPair driving one redundant DP master system on two
// bus::Lines at 1.5 Mbit/s (h_system_test.cpp's header comment has the layout and timing),
// and the no-pulse Sampler. Everything is in an unnamed namespace: each test file has its own.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/s7h/h_system.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/switched_io/switched_station.hpp"

namespace pbvbus::devices {
namespace {


using Bytes = std::vector<std::uint8_t>;
using redundancy::SystemEvent;
using K = SystemEvent::Kind;
using Mode = HSystemModel::SideMode;
using Src = HSystemEvent::Source;

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr std::uint8_t kFast = 5;
constexpr std::uint8_t kSlow = 6;
constexpr std::uint8_t kOneA = 10;
constexpr std::uint8_t kOneB = 11;
constexpr bus::Ticks kT0 = 12 * kMs;
constexpr bus::Ticks kSolo = kT0 + 1000 * kMs;            // 1.012 s
constexpr bus::Ticks kUpdate = kSolo + 2000 * kMs;        // 3.012 s
constexpr bus::Ticks kRedundant = kUpdate + 145 * kMs;    // 3.157 s
constexpr bus::Ticks kScan = 10 * kMs;

GsdFile load(const char* name) {
  auto r = load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name);
  EXPECT_TRUE(r.ok()) << name;
  return *r.file;
}
std::vector<ModuleChoice> switched_modules() {
  return {ModuleChoice::named("16DI DC24V"), ModuleChoice::named("16DO DC24V/0.5A")};
}
std::vector<ModuleChoice> plain_modules() { return {ModuleChoice::named("16DI/16DO DC24V")}; }

struct HSys {
  bus::Scheduler sched;
  bus::Line line[2] = {bus::Line{sched, "A", kBaud}, bus::Line{sched, "B", kBaud}};
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  std::unique_ptr<RedundantMasterSystemModel> sys;
  std::unique_ptr<SwitchedStationModel> st[2];
  std::unique_ptr<SlaveModel> one[2];
  bus::AttachmentId one_att[2] = {-1, -1};
  std::unique_ptr<HSystemModel> h;
  std::uint16_t counter = 0;

  explicit HSys(HCpuPairParams p = {}) {
    bp.hsa = 12;
    const GsdFile fast = load("PBVB0A10.gsd");
    const GsdFile slow = load("PBVB0A11.gsd");
    const GsdFile plain = load("PBVB0A01.gsd");
    std::vector<dp::SlaveParams> cfg[2];
    for (int l = 0; l < 2; ++l) {
      for (auto [gsd, a] : {std::pair{&fast, kFast}, std::pair{&slow, kSlow}}) {
        auto sp = master_slave_params(*gsd, switched_modules(), a);
        EXPECT_TRUE(sp.ok());
        dp::SlaveParams q = *sp.value;
        q.prm_cmd.assign(8, 0);
        cfg[l].push_back(q);
      }
      auto sp = master_slave_params(plain, plain_modules(), l == 0 ? kOneA : kOneB);
      EXPECT_TRUE(sp.ok());
      cfg[l].push_back(*sp.value);
    }
    RedundantMasterSystemOptions o;
    o.bus_params = bp;
    std::vector<redundancy::SwitchedStationRef> refs{{kFast, 30 * kMs, false},
                                                      {kSlow, 820 * kMs, false}};
    sys = std::make_unique<RedundantMasterSystemModel>(o, cfg[0], cfg[1], refs);
    for (int l = 0; l < 2; ++l) sys->attach(l, line[l], "master");
    int k = 0;
    for (auto [gsd, a] : {std::pair{&fast, kFast}, std::pair{&slow, kSlow}}) {
      SwitchedStationOptions so;
      so.address = a;
      so.bus_params = bp;
      auto b = SwitchedStationModel::build(*gsd, switched_modules(), so);
      EXPECT_TRUE(b.ok());
      st[k] = std::move(b.model);
      for (int l = 0; l < 2; ++l) st[k]->attach(l, line[l]);
      ++k;
    }
    for (int l = 0; l < 2; ++l) {
      SlaveModelOptions so;
      so.address = l == 0 ? kOneA : kOneB;
      so.bus_params = bp;
      auto b = SlaveModel::build(plain, plain_modules(), so);
      EXPECT_TRUE(b.ok());
      one[l] = std::move(b.model);
      one_att[l] = line[l].attach(*one[l], "one-sided");
    }
    line[0].start();
    line[1].start();
    h = std::make_unique<HSystemModel>(sched, p, std::vector<RedundantMasterSystemModel*>{sys.get()});
    // OB 1: one counter into every output module (2 octets each, big-endian).
    h->set_program(
        [this](std::span<const std::uint8_t>, std::span<std::uint8_t> piq, bus::Ticks) {
          ++counter;
          for (std::size_t i = 0; i + 1 < piq.size(); i += 2) {
            piq[i] = static_cast<std::uint8_t>(counter >> 8);
            piq[i + 1] = static_cast<std::uint8_t>(counter);
          }
        },
        kScan);
  }
  void run_until(bus::Ticks t) { sched.run_until(t); }
  void at(bus::Ticks t) { sched.run_until(t); }
  redundancy::MasterSystem& ms() { return sys->system(); }
  SwitchedStationModel& station(std::uint8_t a) { return *st[a == kFast ? 0 : 1]; }
  std::vector<SystemEvent> s7() const {
    std::vector<SystemEvent> out;
    for (const auto& e : sys->system().events())
      if (e.s7()) out.push_back(e);
    return out;
  }
  std::vector<HSystemEvent> events(Src s) const {
    std::vector<HSystemEvent> out;
    for (const auto& e : h->events())
      if (e.source == s) out.push_back(e);
    return out;
  }
  std::uint16_t one_outputs(int l) const {
    Bytes b(2);
    one[l]->application().read_outputs(0, b);
    return static_cast<std::uint16_t>((b[0] << 8) | b[1]);
  }
  void bring_up() {
    at(kT0);
    h->power_on_both();
    run_until(kRedundant + 300 * kMs);
  }
};

struct Sampler final : bus::Tap {
  explicit Sampler(HSys& s) : sys(s) {
    s.line[0].add_tap(*this);
    s.line[1].add_tap(*this);
  }
  void on_frame(const bus::TapFrame& f) override {
    for (int k = 0; k < 2; ++k) {
      const auto o = sys.st[k]->outputs();
      samples[k].push_back({f.end, static_cast<std::uint16_t>((o[0] << 8) | o[1])});
    }
  }
  struct Sample {
    bus::Ticks at;
    std::uint16_t value;
  };
  HSys& sys;
  std::vector<Sample> samples[2];
  /// From `from` to `to`, once the first outputs arrived: never 0, never smaller than before.
  void expect_no_pulse(bus::Ticks from, bus::Ticks to = bus::kNever) const {
    for (int k = 0; k < 2; ++k) {
      std::uint16_t last = 0;
      bool started = false;
      for (const auto& s : samples[k]) {
        started = started || s.value != 0;
        if (s.at < from || s.at > to || !started) {
          last = s.value;
          continue;
        }
        ASSERT_NE(s.value, 0) << "station " << k << " outputs 0 at " << s.at;
        ASSERT_GE(s.value, last) << "station " << k << " older value at " << s.at;
        last = s.value;
      }
    }
  }
};


}  // namespace
}  // namespace pbvbus::devices
