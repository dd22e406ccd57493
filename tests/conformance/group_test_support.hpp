#pragma once
// Shared by the tests of the cgrp groups (tests/conformance/group_*_test.cpp): the shipped DUTs
// (examples/gsd/PBVB0A01..04 with the module lists of examples/dp-basic.textproto and
// examples/gateway.textproto), running one group or one test of the battery, and finding a
// result and an exchange of its evidence.

#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/conformance/battery.hpp"
#include "pbvbus/gsd/gsd.hpp"

namespace pbvbus::conformance::testing {

inline std::string gsd_path(const std::string& name) {
  return std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name;
}

/// Parses GSD text (e.g. a shipped file with one keyword changed).
inline std::shared_ptr<const devices::GsdFile> gsd_from_text(const std::string& text,
                                                             const std::string& name) {
  auto r = devices::parse_gsd(text, name);
  EXPECT_TRUE(r.ok()) << name;
  if (!r.ok()) return nullptr;
  return std::make_shared<const devices::GsdFile>(std::move(*r.file));
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A shipped GSD with `from` replaced by `to` (which must occur).
inline std::shared_ptr<const devices::GsdFile> shipped_gsd_with(const std::string& file,
                                                                const std::string& from,
                                                                const std::string& to) {
  std::string text = read_text(gsd_path(file));
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return gsd_from_text(text, file);
}

enum class Shipped { A01, A02, A03, A04 };
inline const char* shipped_name(Shipped s) {
  switch (s) {
    case Shipped::A01:
      return "PBVB0A01";
    case Shipped::A02:
      return "PBVB0A02";
    case Shipped::A03:
      return "PBVB0A03";
    case Shipped::A04:
      return "PBVB0A04";
  }
  return "?";
}
inline constexpr Shipped kAllShipped[] = {Shipped::A01, Shipped::A02, Shipped::A03, Shipped::A04};

/// The slave model of a shipped GSD at address 3, with the modules the example scenarios use.
inline DutSpec shipped(Shipped s, std::optional<devices::SlaveMutant> mutant = std::nullopt,
                       std::shared_ptr<const devices::GsdFile> gsd = nullptr) {
  DutSpec spec;
  spec.gsd_path = gsd_path(std::string(shipped_name(s)) + ".gsd");
  if (!gsd) {
    auto r = devices::load_gsd(spec.gsd_path);
    EXPECT_TRUE(r.ok()) << spec.gsd_path;
    if (r.ok()) gsd = std::make_shared<const devices::GsdFile>(std::move(*r.file));
  }
  spec.gsd = std::move(gsd);
  switch (s) {
    case Shipped::A01:
      break;            // compact station: its one module
    case Shipped::A02:  // examples/dp-basic.textproto, slave 4
      spec.modules = {devices::ModuleChoice::named("8DI DC24V"),
                      devices::ModuleChoice::named("8DO DC24V/0.5A"),
                      devices::ModuleChoice::named("2AO U/I 16 bit")};
      break;
    case Shipped::A03:  // examples/dp-basic.textproto, slave 5
      spec.modules = {devices::ModuleChoice::named("8DI with process alarm"),
                      devices::ModuleChoice::named("8DO DC24V/0.5A"),
                      devices::ModuleChoice::named("2AI U/I consistent")};
      break;
    case Shipped::A04:
      break;  // examples/gateway.textproto, slave 6: its one module
  }
  spec.address = 3;
  spec.mutant = mutant;
  return spec;
}

/// Runs the tests whose id or group is `only`.
inline BatteryReport run_only(const DutSpec& spec, const std::string& only) {
  BatteryOptions o;
  o.only = {only};
  return run_battery(spec, o);
}

inline const TestResult* find_result(const BatteryReport& r, const std::string& id) {
  for (const auto& t : r.results)
    if (t.id == id) return &t;
  return nullptr;
}

/// The first exchange of a result's evidence whose note contains `note`.
inline const Exchange* find_exchange(const TestResult& r, const std::string& note) {
  for (const auto& e : r.evidence)
    if (e.note.find(note) != std::string::npos) return &e;
  return nullptr;
}

inline std::string describe(const BatteryReport& r) {
  std::string s = r.dut_error;
  for (const auto& t : r.results)
    s += "\n  " + t.id + " " + verdict_name(t.verdict) + ": " + t.message;
  return s;
}

/// The verdict of test `id` in `r` (fails the calling test if it is missing).
inline Verdict verdict_of(const BatteryReport& r, const std::string& id) {
  const TestResult* t = find_result(r, id);
  EXPECT_NE(t, nullptr) << id << " missing" << describe(r);
  return t ? t->verdict : Verdict::Fail;
}

}  // namespace pbvbus::conformance::testing
