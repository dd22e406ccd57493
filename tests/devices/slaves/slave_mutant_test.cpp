// The mutant catalogue (devices/slave_mutant.hpp) and SlaveModel built with each mutant: names
// round-trip, every enum value has its row, and each mutant maps to exactly one hook (an
// fdl::PassiveMutation or a dp::EngineMutation), on a GSD that has the features it breaks
// (PBVB0A03: DP-V1 with MSAC_C1, Sync/Freeze, Fail_Safe, consistent modules).
#include "pbvbus/slaves/slave_mutant.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"

namespace pbvbus::devices {
namespace {

constexpr std::size_t kMutantCount = 21;  // the enum's values, counted by hand

TEST(SlaveMutant, EveryEnumValueHasItsRowInOrder) {
  const auto all = slave_mutants();
  ASSERT_EQ(all.size(), kMutantCount);
  std::set<std::string_view> names;
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(static_cast<std::size_t>(all[i].mutant), i);
    EXPECT_FALSE(all[i].rule.empty()) << all[i].name;
    EXPECT_NE(all[i].rule.find("protocol-facts.md"), std::string_view::npos) << all[i].name;
    names.insert(all[i].name);
  }
  EXPECT_EQ(names.size(), kMutantCount) << "names are unique";
}

TEST(SlaveMutant, NamesRoundTrip) {
  for (const MutantInfo& i : slave_mutants()) {
    EXPECT_EQ(parse_slave_mutant(slave_mutant_name(i.mutant)), i.mutant) << i.name;
    EXPECT_EQ(slave_mutant_name(i.mutant), i.name);
  }
  // The spellings scenarios use (docs/mutants.md), checked by hand.
  EXPECT_EQ(parse_slave_mutant("tsdr_too_late"), SlaveMutant::TsdrTooLate);
  EXPECT_EQ(parse_slave_mutant("ignore_fcb"), SlaveMutant::IgnoreFcb);
  EXPECT_EQ(parse_slave_mutant("keep_state_on_power_cycle"), SlaveMutant::KeepStateOnPowerCycle);
  EXPECT_EQ(parse_slave_mutant("wrong_diag_ident"), SlaveMutant::WrongDiagIdent);
  EXPECT_EQ(parse_slave_mutant("dpv1_bad_index_accepted"), SlaveMutant::Dpv1BadIndexAccepted);
  // Unknown, wrong case, empty: nothing.
  EXPECT_EQ(parse_slave_mutant("nope"), std::nullopt);
  EXPECT_EQ(parse_slave_mutant("Ignore_FCB"), std::nullopt);
  EXPECT_EQ(parse_slave_mutant(""), std::nullopt);
}

GsdFile load(const char* name) {
  auto r = load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name);
  EXPECT_TRUE(r.ok()) << name;
  return *r.file;
}

std::vector<ModuleChoice> dv1_modules() {
  return {ModuleChoice::named("8DI with process alarm"), ModuleChoice::named("8DO DC24V/0.5A"),
          ModuleChoice::named("2AI U/I consistent"), ModuleChoice::named("4AI U/I special format")};
}

/// The hook each mutant must end up in, written out by hand.
struct Expected {
  SlaveMutant m;
  dp::EngineMutation engine;
  bool fixed_tsdr, ignore_min_tsdr, ignore_fcb;
  bool shared_fcb = false;
};

TEST(SlaveMutant, EveryMutantBuildsOnPbvb0a03WithExactlyOneHook) {
  using E = dp::EngineMutation;
  using M = SlaveMutant;
  const Expected expected[] = {
      {M::TsdrTooLate, E::None, true, false, false},
      {M::IgnoreMinTsdr, E::None, false, true, false},
      {M::IgnoreFcb, E::None, false, false, true},
      {M::NoPrmReqBit, E::NoPrmReqBit, false, false, false},
      {M::AcceptWrongIdent, E::AcceptWrongIdent, false, false, false},
      {M::IgnoreWatchdog, E::IgnoreWatchdog, false, false, false},
      {M::TearConsistent, E::TearConsistent, false, false, false},
      {M::WrongGetCfg, E::WrongGetCfg, false, false, false},
      {M::IgnoreClearData, E::IgnoreClearData, false, false, false},
      {M::IgnoreLock, E::IgnoreLock, false, false, false},
      {M::AcceptWrongCfg, E::AcceptWrongCfg, false, false, false},
      {M::IgnoreFreeze, E::IgnoreFreeze, false, false, false},
      {M::IgnoreSync, E::IgnoreSync, false, false, false},
      {M::SlowSlaveInterval, E::SlowSlaveInterval, false, false, false},
      {M::KeepStateOnPowerCycle, E::KeepStateOnPowerCycle, false, false, false},
      {M::Dpv1BadIndexAccepted, E::Dpv1BadIndexAccepted, false, false, false},
      {M::RejectFailSafe, E::RejectFailSafe, false, false, false},
      {M::WrongDiagIdent, E::WrongDiagIdent, false, false, false},
      {M::GetCfgSapsNotSwapped, E::GetCfgSapsNotSwapped, false, false, false},
      {M::DataExchangeInWaitCfg, E::DataExchangeInWaitCfg, false, false, false},
      {M::FcbGlobal, E::None, false, false, false, true},
  };
  ASSERT_EQ(std::size(expected), kMutantCount);
  const GsdFile gsd = load("PBVB0A03.gsd");
  for (const Expected& x : expected) {
    SCOPED_TRACE(std::string(slave_mutant_name(x.m)));
    SlaveModelOptions o;
    o.address = 7;
    o.bus_params = fdl::BusParams::defaults(bus::Baud::k1_5M);
    o.mutant = x.m;
    auto b = SlaveModel::build(gsd, dv1_modules(), o);
    ASSERT_TRUE(b.ok()) << (b.errors.empty() ? "" : b.errors.front());
    EXPECT_EQ(b.model->mutant(), x.m);
    EXPECT_EQ(b.model->config().mutation, x.engine);
    const fdl::PassiveMutation& pm = b.model->station().mutation();
    EXPECT_EQ(pm.fixed_tsdr.has_value(), x.fixed_tsdr);
    EXPECT_EQ(pm.ignore_min_tsdr, x.ignore_min_tsdr);
    EXPECT_EQ(pm.ignore_fcb, x.ignore_fcb);
    EXPECT_EQ(pm.shared_fcb, x.shared_fcb);
    if (x.fixed_tsdr) {
      // PBVB0A03: MaxTsdr_1.5M = 150; the mutant answers 20 t_bit later, unbounded.
      EXPECT_EQ(*pm.fixed_tsdr, 170u);
      EXPECT_EQ(b.model->tsdr(), 170u);
      EXPECT_EQ(b.model->station().response_delay(), 170u);
    }
  }
  // Without a mutant: conformant hooks everywhere.
  SlaveModelOptions o;
  o.bus_params = fdl::BusParams::defaults(bus::Baud::k1_5M);
  auto b = SlaveModel::build(gsd, dv1_modules(), o);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b.model->mutant(), std::nullopt);
  EXPECT_EQ(b.model->config().mutation, dp::EngineMutation::None);
  EXPECT_FALSE(b.model->station().mutation().any());
}

TEST(SlaveMutant, TsdrTooLateBypassesOnlyTheMaxTsdrBound) {
  const GsdFile gsd = load("PBVB0A03.gsd");
  SlaveModelOptions o;
  o.bus_params = fdl::BusParams::defaults(bus::Baud::k1_5M);
  o.tsdr = 171;  // beyond MaxTsdr 150: a build error for a conformant model
  auto good = SlaveModel::build(gsd, dv1_modules(), o);
  EXPECT_FALSE(good.ok());
  o.mutant = SlaveMutant::TsdrTooLate;
  auto bad = SlaveModel::build(gsd, dv1_modules(), o);
  ASSERT_TRUE(bad.ok()) << (bad.errors.empty() ? "" : bad.errors.front());
  EXPECT_EQ(bad.model->tsdr(), 170u) << "always MaxTsdr + 20, whatever tsdr says";
  // An unsupported baud rate is still an error (PBVB0A03 has no 31.25 kbit/s).
  o.bus_params = fdl::BusParams::defaults(bus::Baud::k31_25);
  auto baud = SlaveModel::build(gsd, dv1_modules(), o);
  EXPECT_FALSE(baud.ok());
}

}  // namespace
}  // namespace pbvbus::devices
