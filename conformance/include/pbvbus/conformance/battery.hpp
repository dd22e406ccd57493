#pragma once
// The conformance battery (docs/conformance.md): tests of a DP slave against the rules of IEC 61158-6 DP /
// IEC 61784-1 CP 3/1 as PI 2.032 and test labs group them (protocol-facts.md §C–§F). A device
// under test (DUT) is given by its GSD and module list and is either a slave model (a fresh
// devices::SlaveModel per test, optionally a mutant) or an outside slave behind a pty (one
// program for the whole run, reset between tests with an unlocking Set_Prm).
//
// A test is a function over a TestContext: it opens a session (a TestBus with the DUT on it),
// sends telegrams through it, and returns a verdict with a message; the evidence is the
// session's transcript since the test began (the telegrams that decided it). Verdicts:
// Pass, Fail, NotApplicable (the GSD says the feature is absent, or the DUT kind cannot show it —
// e.g. outputs applied to the process are visible only in a model), with the reason.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/conformance/test_bus.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/slaves/slave_mutant.hpp"
#include "pbvbus/dp/master.hpp"

namespace pbvbus::conformance {

/// What the battery is told about the device under test.
struct DutSpec {
  std::shared_ptr<const devices::GsdFile> gsd;
  std::string gsd_path;                          ///< for the report
  std::vector<devices::ModuleChoice> modules;    ///< empty = a compact station's one module
  std::uint8_t address = 3;
  /// Slave model only: one broken rule (devices/slave_mutant.hpp).
  std::optional<devices::SlaveMutant> mutant;
  /// Outside slave: path of the pty the battery creates (its slave side) for the program; unset
  /// = a slave model. With a pty the run is paced at `speed`.
  std::optional<std::string> pty_path;
  bus::Speed speed{1, 1};
  /// The baud of the main session (the TSDR test visits every baud the GSD supports; an outside
  /// slave only this one). Default: the highest the GSD supports up to 1.5 Mbit/s.
  std::optional<bus::Baud> baud;
  /// Outside slave: the wall time a program gets to answer a request (the slot time is made at
  /// least this long in virtual time at `speed`, within TSL <= 16 383 bit times).
  std::chrono::milliseconds reply_wall{100};
  /// Outside slave: how long the battery waits for the program to open the pty before the
  /// first test (then every test is an error: nothing could be tested).
  std::chrono::milliseconds open_wait{30000};
};

/// The battery's times, chosen once per run from the main baud, the longest telegrams the
/// battery sends and expects, and (outside slave) the pace (docs/conformance.md "Timing").
struct TimingPlan {
  std::uint32_t tsl_bits = 0;      ///< slot time of the main sessions
  bus::Ticks longest_request = 0;  ///< the longest telegram the battery sends, on the wire
  bus::Ticks longest_reply = 0;    ///< the longest reply it expects, on the wire
  /// The longest gap between two of the owner's requests in a test's normal flow: TSYN +
  /// longest request + TSL + longest reply + the Data_Exchange spacing.
  bus::Ticks exchange_span = 0;
  /// Outside slave: a program's wall-clock jitter (30 ms) in virtual time at the pace; 0 else.
  bus::Ticks pace_jitter = 0;
  /// The watchdog tests' TWD (PRM-06/07, INT-01..04, C2-04): a multiple of 10 ms, at least
  /// 100 ms, at least 4 × exchange_span and at least 4 × wd_margin.
  bus::Ticks twd = 0;
  /// Distance of the checks before and after the expiry from TWD: 1 % of TWD (at least 1 ms)
  /// for a model (exact); for a program also where it may start its watchdog (the start or the
  /// end of the last request, or its own reply) and twice the pace jitter.
  bus::Ticks wd_margin = 0;
  /// Outside slave: the wall time the slot time gives a program to answer.
  std::chrono::milliseconds reply_wall{0};
  /// One line for the report header.
  std::string summary() const;
};

/// The fastest pace (virtual/wall) at which a slot time within 16 383 bit times still gives a
/// program `reply_wall` of wall time to answer at `baud`: 1/1, 1/2, 1/5, 1/10, 1/20, 1/50, ...
bus::Speed auto_speed(bus::Baud baud, std::chrono::milliseconds reply_wall);

/// Error: the test's precondition (the state it starts from: owner, state, address; or a session
/// at all) could not be established, so its rule was not tested — neither pass nor fail.
enum class Verdict : std::uint8_t { Pass, Fail, NotApplicable, Error };
const char* verdict_name(Verdict v);  ///< "pass", "fail", "n/a", "error"

struct TestResult {
  std::string id;           ///< stable, e.g. "PRM-03"
  std::string group;        ///< e.g. "Set_Prm"
  std::string name;         ///< short title
  std::string requirement;  ///< the rule checked, in words, citing the standard's clause
  Verdict verdict = Verdict::Pass;
  std::string message;      ///< why (for Fail/NotApplicable: what was expected and what came)
  std::vector<Exchange> evidence;  ///< the telegrams that decided it
  /// Set when the DUT is paced behind a pty and this test's timing checks are meaningless there.
  bool timing_not_meaningful = false;
};

/// One session: a TestBus at a baud with the DUT attached and powered. For a model it is a fresh
/// model; for an outside slave the same program (its pty attached to this bus).
class Session {
 public:
  virtual ~Session() = default;
  virtual TestBus& bus() = 0;
  /// The DUT's FDL address (changes after a successful Set_Slave_Add).
  virtual std::uint8_t dut_address() const = 0;
  /// White box: the slave model, or nullptr for an outside slave.
  virtual devices::SlaveModel* model() = 0;
  /// The exchanges of this session since it was opened (its own, not earlier tests').
  virtual std::span<const Exchange> exchanges() const = 0;
};

class TestContext {
 public:
  virtual ~TestContext() = default;
  const DutSpec& spec() const { return *m_spec; }
  /// What a configuration tool gives a class-1 master for the DUT (Set_Prm with the
  /// GSD-assembled User_Prm_Data, Chk_Cfg, ident, Min_Slave_Interval, Fail_Safe), address
  /// = spec().address, master = the tester.
  const dp::SlaveParams& params() const { return m_params; }
  /// Inputs/outputs lengths of the DUT's configuration (octets).
  std::size_t input_len() const { return m_in; }
  std::size_t output_len() const { return m_out; }
  bool outside() const { return m_spec->pty_path.has_value(); }
  /// The run's times (slot time, watchdog, margins).
  const TimingPlan& timing() const { return m_timing; }
  /// Opens a session at `baud` (the spec's main baud if unset). nullptr + `error` when the DUT
  /// cannot run there (an outside slave at another baud, a baud the GSD lacks).
  virtual std::unique_ptr<Session> open(std::optional<bus::Baud> baud, std::string& error) = 0;

 protected:
  const DutSpec* m_spec = nullptr;
  dp::SlaveParams m_params;
  std::size_t m_in = 0;
  std::size_t m_out = 0;
  TimingPlan m_timing;
};

/// A test: its identity and its body. The body fills verdict, message and evidence of `result`
/// (id, group, name and requirement are copied from the case before it runs).
struct TestCase {
  std::string id;
  std::string group;
  std::string name;
  std::string requirement;
  std::function<void(TestContext& ctx, TestResult& result)> run;
  /// The mutants (devices/slave_mutant.hpp) whose broken rule this test checks: the mutation
  /// score counts a mutant as killed when one of the tests aimed at it fails.
  std::vector<devices::SlaveMutant> targets;
};

/// Every test of the battery, in report order (groups in a fixed order).
const std::vector<TestCase>& all_tests();

struct BatteryOptions {
  /// Only tests whose id or group matches one of these (exact id, or group name); empty = all.
  std::vector<std::string> only;
  /// Told what the runner waits for (an outside slave: the program opening the pty).
  std::function<void(const std::string&)> progress;
};

struct BatteryReport {
  DutSpec spec;
  TimingPlan timing;  ///< the times the run used
  std::vector<TestResult> results;
  std::string dut_error;  ///< the DUT could not be built at all (then no results)
  std::size_t count(Verdict v) const;
  /// Nothing failed and nothing was left untested by an error (n/a is neither).
  bool passed() const {
    return dut_error.empty() && count(Verdict::Fail) == 0 && count(Verdict::Error) == 0;
  }
};

/// Runs the battery. Never throws on a bad DUT: a DUT that cannot be built is dut_error.
BatteryReport run_battery(const DutSpec& spec, const BatteryOptions& options = {});

/// (Addition by cbat.) The main baud of a DUT: spec.baud, else the highest rate its GSD supports
/// up to 1.5 Mbit/s, else the GSD's lowest rate (1.5 Mbit/s without a GSD).
bus::Baud dut_main_baud(const DutSpec& spec);

}  // namespace pbvbus::conformance
