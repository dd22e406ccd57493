// `pbvbus conformance`: the conformance battery against a DP slave (conformance/battery.hpp;
// docs/conformance.md).
//
//   pbvbus conformance --gsd FILE [--module NAME]... [--address N] [--baud B] [--mutant NAME]
//                      [--pty PATH --speed N/M] [--only ID|GROUP]... [--json] [--junit FILE]
//   pbvbus conformance --scenario FILE --station ADDR|NAME [same options]
//   pbvbus conformance --mutation-score [--markdown] [--gsd FILE [--module NAME]...]
//
// Decisions:
// - --scenario takes the slave's GSD, modules and address from a scenario's dp_slave (loaded and
//   planned like `pbvbus run` does), and its line's baud unless --baud is given. NAME matches the
//   GSD's Model_Name or the GSD file name.
// - Exit status: 0 every test passed (n/a counts as passed), 1 a test failed, 2 bad usage or bad
//   input (unreadable or broken GSD, unknown module or mutant, a baud the GSD lacks: the DUT
//   cannot be built), 3 nothing failed but some test could not establish its precondition
//   (verdict error: its rule was not tested, so the run proves less than it claims). --mutation-score: 0 only if every score is 100 % and every unbroken model
//   passes, else 1.
// - --mutation-score without --gsd scores the shipped GSDs PBVB0A01..04 with the module lists
//   of examples/gateway.textproto (the dp-basic slaves 3..5 plus the gateway test station 6);
//   the examples folder is the one the binary was built from (as for the default scenario).

#include <charconv>
#include <fstream>
#include <iostream>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "pbvbus/conformance/battery.hpp"
#include "pbvbus/conformance/mutation.hpp"
#include "pbvbus/conformance/report.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/tools/commands.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

constexpr const char* kConformanceUsage =
    "usage: pbvbus conformance --gsd FILE [--module NAME]... [--address N] [--baud B]\n"
    "                          [--mutant NAME] [--pty PATH --speed N/M] [--only ID|GROUP]...\n"
    "                          [--json] [--junit FILE]\n"
    "       pbvbus conformance --scenario FILE --station ADDR|NAME [options as above]\n"
    "       pbvbus conformance --mutation-score [--markdown] [--gsd FILE [--module NAME]...]\n"
    "\n"
    "Runs the conformance battery against a DP slave (docs/conformance.md): start-up and\n"
    "diagnosis, Set_Prm, Chk_Cfg, read services, FCB/FCV and the other groups; each test with\n"
    "an id, the requirement it checks, a verdict (pass, fail, n/a) and the telegrams that\n"
    "decided it.\n"
    "\n"
    "  --gsd FILE          the DUT's GSD file\n"
    "  --module NAME       a module of the GSD (repeat in slot order; \"#N\" = the N-th module,\n"
    "                      from 0); none = the compact station's one module\n"
    "  --address N         the DUT's FDL address (default 3)\n"
    "  --baud B            main baud, e.g. 1.5M, 187.5k (default: the highest the GSD supports\n"
    "                      up to 1.5M)\n"
    "  --mutant NAME       a slave model that breaks one rule (docs/mutants.md)\n"
    "  --pty PATH          the DUT is an outside program: the battery creates a pty and links\n"
    "                      PATH to it; the program opens PATH as its serial port\n"
    "  --speed N/M         virtual/wall time ratio with --pty (default: the fastest of 1/1, 1/2,\n"
    "                      1/5, 1/10, ... that gives the program 100 ms of wall time per reply\n"
    "                      within a slot time of 16 383 bit times: 1/1 up to 93.75k, 1/2 at\n"
    "                      187.5k, 1/10 at 1.5M)\n"
    "  --only ID|GROUP     run only these tests (exact id or group name; repeat)\n"
    "  --scenario FILE     take GSD, modules, address and baud from a scenario's dp_slave ...\n"
    "  --station ADDR|NAME ... at this address (or GSD Model_Name / file name)\n"
    "  --json              print the report as JSON (schema pbvbus.conformance/1)\n"
    "  --junit FILE        also write a JUnit XML report (one testsuite per group)\n"
    "  --mutation-score    run every mutant and print the table mutant x failing tests\n"
    "  --markdown          with --mutation-score: the table as markdown\n"
    "  -h, --help          this text\n"
    "\n"
    "Exit status: 0 nothing failed, 1 a test failed (with --mutation-score: a score below\n"
    "100 % or a failing unbroken model), 2 bad usage or bad input, 3 no failure but a test\n"
    "whose precondition could not be established (verdict error).\n";

std::optional<bus::Speed> parse_ratio(const std::string& v) {
  auto num = [](std::string_view t) -> std::optional<std::uint32_t> {
    std::uint32_t x = 0;
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), x);
    if (ec != std::errc() || p != t.data() + t.size() || x == 0) return std::nullopt;
    return x;
  };
  const auto slash = v.find('/');
  auto n = num(std::string_view(v).substr(0, slash));
  auto d = slash == std::string::npos ? std::optional<std::uint32_t>(1) : num(std::string_view(v).substr(slash + 1));
  if (!n || !d) return std::nullopt;
  return bus::Speed{*n, *d};
}

std::optional<unsigned> parse_uint(const std::string& v, unsigned max) {
  unsigned x = 0;
  auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
  if (ec != std::errc() || p != v.data() + v.size() || x > max) return std::nullopt;
  return x;
}

struct Options {
  std::optional<std::string> gsd;
  std::vector<std::string> modules;
  std::optional<unsigned> address;
  std::optional<bus::Baud> baud;
  std::optional<devices::SlaveMutant> mutant;
  std::optional<std::string> pty;
  std::optional<bus::Speed> speed;
  std::vector<std::string> only;
  std::optional<std::string> scenario;
  std::optional<std::string> station;
  bool json = false;
  std::optional<std::string> junit;
  bool mutation = false;
  bool markdown = false;
};

/// Loads a GSD for the battery; "" or the reason.
std::string load_gsd_file(const std::string& path, std::shared_ptr<const devices::GsdFile>& out) {
  auto r = devices::load_gsd(path);
  if (!r.ok()) {
    std::string why;
    for (const auto& e : r.errors) why += "\n  " + e.to_string();
    return "cannot use GSD " + path + ":" + why;
  }
  out = std::make_shared<const devices::GsdFile>(std::move(*r.file));
  return {};
}

/// The shipped examples folder (the one the default scenario names), with a trailing '/'.
std::string examples_dir() {
  const std::string_view t = default_scenario_text();
  // Its dp_slave entries read `gsd: "<examples>/gsd/PBVB0A10.gsd"`.
  const std::string_view key = "gsd: \"";
  const auto at = t.find(key);
  if (at != std::string_view::npos) {
    const auto from = at + key.size();
    const auto end = t.find("/gsd/", from);
    const auto quote = t.find('"', from);
    if (end != std::string_view::npos && end < quote) return std::string(t.substr(from, end - from)) + "/";
  }
  return "examples/";
}

/// The DUT of a scenario's dp_slave; "" or the reason.
std::string spec_from_scenario(const Options& o, conformance::DutSpec& spec) {
  const LoadResult loaded = load_scenario_file(*o.scenario);
  if (!loaded.ok()) {
    std::string why;
    for (const auto& d : loaded.errors) why += "\n  " + d.str();
    return "cannot load scenario " + *o.scenario + ":" + why;
  }
  const ScenarioPlan& plan = *loaded.plan;
  const auto addr = parse_uint(*o.station, 126);
  for (const DpSlavePlan& s : plan.dp_slaves) {
    const std::string file = s.gsd_path.substr(s.gsd_path.find_last_of('/') + 1);
    if (addr ? s.address != *addr : (s.model != *o.station && file != *o.station)) continue;
    spec.gsd = s.gsd;
    spec.gsd_path = s.gsd_path;
    spec.address = s.address;
    for (const auto& m : s.module_names) spec.modules.push_back(devices::ModuleChoice::named(m));
    if (!o.baud && s.line >= 0 && static_cast<std::size_t>(s.line) < plan.lines.size())
      spec.baud = plan.lines[static_cast<std::size_t>(s.line)].params.baud;
    return {};
  }
  return "scenario " + *o.scenario + " has no dp_slave " + *o.station;
}

int run_mutation(const Options& o, std::ostream& out, std::ostream& err) {
  std::vector<conformance::DutSpec> specs;
  if (o.gsd) {
    conformance::DutSpec s;
    if (auto why = load_gsd_file(*o.gsd, s.gsd); !why.empty()) {
      err << "pbvbus conformance: " << why << "\n";
      return 2;
    }
    s.gsd_path = *o.gsd;
    for (const auto& m : o.modules) s.modules.push_back(devices::ModuleChoice::parse(m));
    if (o.address) s.address = static_cast<std::uint8_t>(*o.address);
    s.baud = o.baud;
    specs.push_back(std::move(s));
  } else {
    Options so;
    so.scenario = examples_dir() + "gateway.textproto";
    for (const char* st : {"3", "4", "5", "6"}) {
      so.station = st;
      conformance::DutSpec s;
      if (auto why = spec_from_scenario(so, s); !why.empty()) {
        err << "pbvbus conformance: " << why << "\n";
        return 2;
      }
      specs.push_back(std::move(s));
    }
  }
  std::vector<conformance::MutationReport> reports;
  bool ok = true;
  for (const auto& s : specs) {
    reports.push_back(conformance::mutation_score(s));
    const auto& r = reports.back();
    ok = ok && r.unbroken_passed && r.count(conformance::MutantStatus::Survived) == 0 &&
         r.count(conformance::MutantStatus::Error) == 0;
  }
  out << (o.markdown ? conformance::mutation_table_markdown(reports) : conformance::mutation_table_text(reports));
  return ok ? 0 : 1;
}

}  // namespace

int cmd_conformance(const Args& args, std::ostream& out, std::ostream& err) {
  Options o;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* name) -> std::optional<std::string> {
      if (i + 1 >= args.size()) {
        err << "pbvbus conformance: " << name << " needs a value\n";
        return std::nullopt;
      }
      return args[++i];
    };
    if (a == "-h" || a == "--help") {
      out << kConformanceUsage;
      return 0;
    } else if (a == "--gsd") {
      auto v = value("--gsd");
      if (!v) return 2;
      o.gsd = *v;
    } else if (a == "--module") {
      auto v = value("--module");
      if (!v) return 2;
      o.modules.push_back(*v);
    } else if (a == "--address") {
      auto v = value("--address");
      if (!v) return 2;
      o.address = parse_uint(*v, 125);
      if (!o.address) {
        err << "pbvbus conformance: --address must be 0..125, not '" << *v << "'\n";
        return 2;
      }
    } else if (a == "--baud") {
      auto v = value("--baud");
      if (!v) return 2;
      o.baud = bus::parse_baud(*v);
      if (!o.baud) {
        err << "pbvbus conformance: unknown baud rate '" << *v << "'\n";
        return 2;
      }
    } else if (a == "--mutant") {
      auto v = value("--mutant");
      if (!v) return 2;
      o.mutant = devices::parse_slave_mutant(*v);
      if (!o.mutant) {
        err << "pbvbus conformance: unknown mutant '" << *v << "'; known:";
        for (const auto& m : devices::slave_mutants()) err << " " << m.name;
        err << "\n";
        return 2;
      }
    } else if (a == "--pty") {
      auto v = value("--pty");
      if (!v) return 2;
      o.pty = *v;
    } else if (a == "--speed") {
      auto v = value("--speed");
      if (!v) return 2;
      o.speed = parse_ratio(*v);
      if (!o.speed) {
        err << "pbvbus conformance: --speed must be N or N/M with positive integers, not '" << *v << "'\n";
        return 2;
      }
    } else if (a == "--only") {
      auto v = value("--only");
      if (!v) return 2;
      o.only.push_back(*v);
    } else if (a == "--scenario") {
      auto v = value("--scenario");
      if (!v) return 2;
      o.scenario = *v;
    } else if (a == "--station") {
      auto v = value("--station");
      if (!v) return 2;
      o.station = *v;
    } else if (a == "--json") {
      o.json = true;
    } else if (a == "--junit") {
      auto v = value("--junit");
      if (!v) return 2;
      o.junit = *v;
    } else if (a == "--mutation-score") {
      o.mutation = true;
    } else if (a == "--markdown") {
      o.markdown = true;
    } else {
      err << "pbvbus conformance: unknown argument '" << a << "'\n" << kConformanceUsage;
      return 2;
    }
  }

  if (o.mutation) {
    if (o.pty || o.mutant || o.scenario) {
      err << "pbvbus conformance: --mutation-score works on slave models from --gsd (no --pty, --mutant, "
             "--scenario)\n";
      return 2;
    }
    return run_mutation(o, out, err);
  }
  if (o.gsd.has_value() == o.scenario.has_value()) {
    err << "pbvbus conformance: give either --gsd FILE or --scenario FILE --station ADDR|NAME\n" << kConformanceUsage;
    return 2;
  }
  if (o.scenario && !o.station) {
    err << "pbvbus conformance: --scenario needs --station ADDR|NAME\n";
    return 2;
  }
  if (o.speed && !o.pty) {
    err << "pbvbus conformance: --speed only with --pty\n";
    return 2;
  }
  if (o.pty && o.mutant) {
    err << "pbvbus conformance: --mutant is for slave models, not with --pty\n";
    return 2;
  }

  conformance::DutSpec spec;
  if (o.scenario) {
    if (auto why = spec_from_scenario(o, spec); !why.empty()) {
      err << "pbvbus conformance: " << why << "\n";
      return 2;
    }
    if (!o.modules.empty()) {
      spec.modules.clear();
      for (const auto& m : o.modules) spec.modules.push_back(devices::ModuleChoice::parse(m));
    }
  } else {
    if (auto why = load_gsd_file(*o.gsd, spec.gsd); !why.empty()) {
      err << "pbvbus conformance: " << why << "\n";
      return 2;
    }
    spec.gsd_path = *o.gsd;
    for (const auto& m : o.modules) spec.modules.push_back(devices::ModuleChoice::parse(m));
  }
  if (o.address) spec.address = static_cast<std::uint8_t>(*o.address);
  if (o.baud) spec.baud = o.baud;
  spec.mutant = o.mutant;
  if (o.pty) {
    spec.pty_path = *o.pty;
    // Default pace: the fastest at which a slot time within the standard's 16 383 bit times
    // still gives the program spec.reply_wall (100 ms) of wall time to answer (battery.hpp).
    spec.speed = o.speed.value_or(conformance::auto_speed(conformance::dut_main_baud(spec), spec.reply_wall));
  }
  if (spec.gsd && spec.gsd->is_master()) {
    err << "pbvbus conformance: " << spec.gsd_path << " describes a DP master, not a slave\n";
    return 2;
  }

  conformance::BatteryOptions bo;
  bo.only = o.only;
  bo.progress = [&err](const std::string& m) { err << "pbvbus conformance: " << m << std::endl; };
  if (!bo.only.empty()) {
    for (const auto& sel : bo.only) {
      bool known = false;
      for (const auto& t : conformance::all_tests()) known = known || t.id == sel || t.group == sel;
      if (!known) {
        err << "pbvbus conformance: --only '" << sel << "' matches no test id or group\n";
        return 2;
      }
    }
  }
  const conformance::BatteryReport report = conformance::run_battery(spec, bo);
  out << (o.json ? conformance::to_json(report) : conformance::to_text(report));
  if (o.junit) {
    std::ofstream f(*o.junit, std::ios::binary | std::ios::trunc);
    f << conformance::to_junit(report);
    if (!f) {
      err << "pbvbus conformance: cannot write " << *o.junit << "\n";
      return 2;
    }
  }
  if (!report.dut_error.empty()) {
    err << "pbvbus conformance: the DUT cannot be built: " << report.dut_error << "\n";
    return 2;
  }
  if (report.count(conformance::Verdict::Fail) > 0) return 1;
  return report.count(conformance::Verdict::Error) > 0 ? 3 : 0;
}

}  // namespace pbvbus::tools
