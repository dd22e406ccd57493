// `pbvbus replay CAPTURE ...` (docs/replay.md): the command line around the
// replay core in conformance/ (replay_input.hpp, replay.hpp, replay_serial.hpp).
//
// Three forms:
//  - against a scenario: the scenario's stations on the capture's line are built WITHOUT its
//    masters (SimulationOptions::omit_masters); the Replayer takes the first master's cable
//    position (extra_device); the run is fast (virtual time as fast as the CPU allows);
//  - against an outside slave behind a pty (--pty PATH --station ADDR): a line with a
//    bus::PtyStation at ADDR (PATH a symlink to it) and the Replayer, run paced at --speed
//    (default 1/1000, so that a program can answer within the slot time);
//  - --to PTY: the capture's frames raw into a serial port for an analyzer (replay_serial.hpp).
//
// Decisions:
//  - TSL for pairing and the replay is the scenario line's (pty form: the DP profile's for the
//    capture's baud); the TSDR window is [min TSDR of the line (11 by default), the line's max
//    TSDR], overridable with --min-tsdr/--max-tsdr.
//  - Bad input (not a capture, no such line, a bad scenario, a bad option) is exit 2 with a
//    message; unusable records are not bad input: they are listed and the replay runs on.
//  - Scenarios with redundant master systems, H-systems or gateways are refused (their
//    masters cannot be left out frame by frame; exit 2).

#include <sys/stat.h>
#include <unistd.h>

#include <boost/asio/steady_timer.hpp>
#include <charconv>
#include <chrono>
#include <functional>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/pty_station.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/conformance/replay.hpp"
#include "pbvbus/conformance/replay_serial.hpp"
#include "pbvbus/slaves/slave_mutant.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/tools/commands.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {

namespace {

namespace cf = conformance;

constexpr const char* kReplayUsage =
    "usage: pbvbus replay CAPTURE --scenario FILE [--station ADDR] [--mutant ADDR:NAME]...\n"
    "                     [--line NAME] [--paced-as-recorded | --fast] [--mask RULE]...\n"
    "                     [--max-diffs N] [--min-tsdr N] [--max-tsdr N] [--json]\n"
    "       pbvbus replay CAPTURE --pty PATH --station ADDR [--speed N/M] [--line NAME]\n"
    "                     [--paced-as-recorded | --fast] [--mask RULE]... [--json]\n"
    "       pbvbus replay CAPTURE --to PTY [--speed N/M] [--line NAME]\n"
    "\n"
    "Sends the capture's initiator frames (requests, tokens, Global_Control) again, verbatim, to\n"
    "a target and compares every reply octet by octet with the recorded one.\n"
    "\n"
    "  --scenario FILE      the target: the scenario's stations on the capture's line, its\n"
    "                       masters left out (the replayer takes the first one's place)\n"
    "  --station ADDR       replay only the requests to ADDR (and broadcasts); default: all\n"
    "                       frames, tokens included\n"
    "  --mutant ADDR:NAME   make DP slave ADDR a mutant (docs/mutants.md)\n"
    "  --pty PATH           the target is an outside slave behind a pty linked at PATH\n"
    "                       (needs --station); the run is paced at --speed (default 1/1000)\n"
    "  --to PTY             play the frames raw into a serial port: PTY an existing tty, or a\n"
    "                       new pty linked at PTY; original pacing scaled by --speed (default 1)\n"
    "  --line NAME          the capture's line (interface name); default the first\n"
    "  --paced-as-recorded  send each frame at its recorded time (late replies: pacing slips)\n"
    "  --fast               send each frame after the previous exchange (default)\n"
    "  --mask RULE          compare masked octets as equal: inputs, diag-ext,\n"
    "                       counter:ADDR:OFFSET[-END], ADDR:SAP:OFFSET[-END] (SAP dx =\n"
    "                       Data_Exchange; DU offsets from 0); repeatable\n"
    "  --max-diffs N        differences shown in full (default 10)\n"
    "  --min-tsdr N, --max-tsdr N   the reply-time window in bit times\n"
    "  --json               the report as JSON (schema pbvbus.replay/1)\n"
    "\n"
    "Exit status: 0 no differences, 1 differences, 2 bad usage or bad input.\n";

struct ReplayArgs {
  std::string capture;
  std::optional<std::string> scenario, pty, to;
  std::optional<std::uint8_t> station;
  std::vector<std::pair<std::uint8_t, std::string>> mutants;
  std::string line;
  cf::ReplayPacing pacing = cf::ReplayPacing::Fast;
  std::vector<cf::ReplayMask> masks;
  std::size_t max_diffs = 10;
  std::optional<std::uint32_t> min_tsdr, max_tsdr;
  std::optional<bus::Speed> speed;
  bool json = false;
  bool help = false;
};

template <class T>
std::optional<T> number(const std::string& s, T max) {
  unsigned long long v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || s.empty() || v > max) return std::nullopt;
  return static_cast<T>(v);
}

std::optional<bus::Speed> parse_replay_speed(const std::string& v) {
  const auto slash = v.find('/');
  auto n = number<std::uint32_t>(v.substr(0, slash), 1'000'000'000);
  auto d = slash == std::string::npos ? std::optional<std::uint32_t>(1)
                                      : number<std::uint32_t>(v.substr(slash + 1), 1'000'000'000);
  if (!n || !d || *n == 0 || *d == 0) return std::nullopt;
  return bus::Speed{*n, *d};
}

/// Makes the planned slave a mutant (DpSlavePlan::mutant, as `dp_slave { mutant: ... }`
/// would); "" or why not.
std::string set_slave_mutant(DpSlavePlan& s, const std::string& name) {
  if (s.switched >= 0) return "a switched station's interface cannot be a mutant";
  s.mutant = devices::parse_slave_mutant(name);
  return "";
}

/// "" on success, else the message.
std::string parse_args(const Args& args, ReplayArgs& out) {
  bool pacing_given = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* opt) -> std::optional<std::string> {
      if (i + 1 >= args.size()) return std::nullopt;
      (void)opt;
      return args[++i];
    };
    auto need = [&](const char* opt, std::optional<std::string>& dst) -> std::string {
      auto v = value(opt);
      if (!v) return std::string(opt) + " needs a value";
      dst = *v;
      return "";
    };
    if (a == "--help" || a == "-h") {
      out.help = true;
    } else if (a == "--json") {
      out.json = true;
    } else if (a == "--scenario") {
      if (auto e = need("--scenario", out.scenario); !e.empty()) return e;
    } else if (a == "--pty") {
      if (auto e = need("--pty", out.pty); !e.empty()) return e;
    } else if (a == "--to") {
      if (auto e = need("--to", out.to); !e.empty()) return e;
    } else if (a == "--line") {
      auto v = value("--line");
      if (!v) return "--line needs a value";
      out.line = *v;
    } else if (a == "--station") {
      auto v = value("--station");
      auto n = v ? number<std::uint8_t>(*v, 126) : std::nullopt;
      if (!n) return "--station needs an address 0..126";
      out.station = *n;
    } else if (a == "--mutant") {
      auto v = value("--mutant");
      const auto colon = v ? v->find(':') : std::string::npos;
      auto n = colon != std::string::npos ? number<std::uint8_t>(v->substr(0, colon), 126) : std::nullopt;
      if (!n) return "--mutant needs ADDR:NAME, e.g. 4:tsdr_too_late";
      const std::string name = v->substr(colon + 1);
      if (!devices::parse_slave_mutant(name)) {
        std::string known;
        for (const auto& m : devices::slave_mutants()) known += " " + std::string(m.name);
        return "unknown mutant '" + name + "' (known:" + known + ")";
      }
      out.mutants.emplace_back(*n, name);
    } else if (a == "--paced-as-recorded" || a == "--fast") {
      const auto p = a == "--fast" ? cf::ReplayPacing::Fast : cf::ReplayPacing::AsRecorded;
      if (pacing_given && p != out.pacing) return "--paced-as-recorded and --fast exclude each other";
      pacing_given = true;
      out.pacing = p;
    } else if (a == "--mask") {
      auto v = value("--mask");
      if (!v) return "--mask needs a rule";
      std::string e;
      auto m = cf::parse_replay_mask(*v, e);
      if (!m) return e;
      out.masks.push_back(*m);
    } else if (a == "--max-diffs") {
      auto v = value("--max-diffs");
      auto n = v ? number<std::size_t>(*v, 1'000'000) : std::nullopt;
      if (!n) return "--max-diffs needs a number";
      out.max_diffs = *n;
    } else if (a == "--min-tsdr" || a == "--max-tsdr") {
      auto v = value(a.c_str());
      auto n = v ? number<std::uint32_t>(*v, fdl::BusParams::kTslMax) : std::nullopt;
      if (!n) return a + " needs a number of bit times";
      (a == "--min-tsdr" ? out.min_tsdr : out.max_tsdr) = *n;
    } else if (a == "--speed") {
      auto v = value("--speed");
      auto sp = v ? parse_replay_speed(*v) : std::nullopt;
      if (!sp) return "--speed needs N or N/M with positive integers, e.g. 1/1000";
      out.speed = *sp;
    } else if (a.size() > 1 && a[0] == '-') {
      return "unknown option '" + a + "'";
    } else if (out.capture.empty()) {
      out.capture = a;
    } else {
      return "more than one capture given ('" + out.capture + "', '" + a + "')";
    }
  }
  if (out.help) return "";
  if (out.capture.empty()) return "no capture given";
  const int forms = (out.scenario ? 1 : 0) + (out.pty ? 1 : 0) + (out.to ? 1 : 0);
  if (forms != 1) return "give exactly one of --scenario FILE, --pty PATH, --to PTY";
  if (out.pty && !out.station) return "--pty needs --station ADDR (the outside slave's address)";
  if (!out.mutants.empty() && !out.scenario) return "--mutant needs --scenario";
  if (out.speed && out.scenario) return "--speed applies to --pty and --to only";
  return "";
}

std::optional<std::vector<std::uint8_t>> read_file(const std::string& path, std::string& error) {
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    error = "cannot open '" + path + "'";
    return std::nullopt;
  }
  std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (data.empty()) {
    error = "'" + path + "' is empty: not a pcapng file";
    return std::nullopt;
  }
  return data;
}

/// Virtual time the replay may take at most: the recorded span plus, per frame sent, a slot
/// time and a longest frame (a fast replay is never longer), plus a second.
bus::Ticks time_cap(const cf::ReplayInput& in, const cf::Replayer& r) {
  const bus::Ticks span = in.frames.empty() ? 0 : in.frames.back().end - in.frames.front().start;
  const bus::Ticks per = bus::bits_to_ticks(in.tsl + 33, in.baud) +
                         bus::chars_to_ticks(fdl::kMaxFrame, in.baud);
  return span + static_cast<bus::Ticks>(r.plan().size() + 2) * per + bus::kTicksPerSecond;
}

int report(const ReplayArgs& ra, const cf::ReplayResult& res, std::ostream& out) {
  out << (ra.json ? cf::replay_json(res, ra.max_diffs) : cf::replay_text(res, ra.max_diffs));
  return cf::replay_exit_status(res);
}

int run_to(const ReplayArgs& ra, const std::vector<std::uint8_t>& data, std::ostream& out,
           std::ostream& err) {
  // An existing character device (a tty, a pty someone else made) is opened; anything else
  // becomes the symlink to a new pty.
  struct stat st {};
  const bool existing = ::stat(ra.to->c_str(), &st) == 0 && S_ISCHR(st.st_mode);
  std::string e;
  auto target = cf::open_serial_target(*ra.to, !existing, e);
  if (!target) {
    err << "pbvbus replay: " << e << "\n";
    return 2;
  }
  err << "pbvbus replay: playing into " << target->path()
      << (existing ? std::string() : " (linked at " + *ra.to + ")") << "\n";
  cf::SerialPlayOptions o;
  o.line = ra.line;
  if (ra.speed) {
    o.speed_num = ra.speed->num;
    o.speed_den = ra.speed->den;
  }
  auto stats = cf::play_to_serial(data, *target, o, e);
  if (!stats) {
    err << "pbvbus replay: " << ra.capture << ": " << e << "\n";
    return 2;
  }
  if (ra.json) {
    out << "{\"schema\":\"pbvbus.replay.serial/1\",\"frames\":" << stats->frames
        << ",\"frames_written\":" << stats->frames_written << ",\"frames_dropped\":" << stats->frames_dropped
        << ",\"octets_written\":" << stats->octets_written << ",\"octets_dropped\":" << stats->octets_dropped
        << ",\"wall_ms\":" << stats->wall_ms << "}\n";
  } else {
    out << "played " << stats->frames_written << " of " << stats->frames << " frames into "
        << target->path() << " in " << stats->wall_ms << " ms: " << stats->octets_written
        << " octets written, " << stats->frames_dropped << " frames and " << stats->octets_dropped
        << " octets dropped (reader not reading)\n";
  }
  return 0;
}

int run_pty(const ReplayArgs& ra, const cf::ReplayInput& in, std::ostream& out, std::ostream& err) {
  bus::Scheduler sched;
  bus::Line line(sched, in.line.empty() ? "replay" : in.line, in.baud);
  bus::PtyStation::Options po;
  po.mode = bus::PtyStation::Mode::Station;
  po.address = *ra.station;
  po.reply_window_bits = in.tsl;
  std::unique_ptr<bus::PtyStation> pty;
  try {
    pty = std::make_unique<bus::PtyStation>(po);
  } catch (const std::exception& ex) {
    err << "pbvbus replay: cannot open a pseudo-terminal: " << ex.what() << "\n";
    return 2;
  }
  struct stat st {};
  if (::lstat(ra.pty->c_str(), &st) == 0) {
    if (!S_ISLNK(st.st_mode)) {
      err << "pbvbus replay: cannot link the pty to " << *ra.pty << ": a file of that name exists\n";
      return 2;
    }
    ::unlink(ra.pty->c_str());
  }
  if (::symlink(pty->path().c_str(), ra.pty->c_str()) != 0) {
    err << "pbvbus replay: cannot link the pty to " << *ra.pty << "\n";
    return 2;
  }
  cf::Replayer rp(in, {ra.pacing, ra.station});
  line.attach(rp, "replayer");
  line.attach(*pty, "serial station " + std::to_string(*ra.station));
  int rc = 0;
  {
    bus::PacedRunner runner(sched, ra.speed.value_or(bus::Speed{1, 1000}));
    pty->attach_io(runner);
    line.start();
    const bus::Ticks cap = time_cap(in, rp);
    // ONE run up to the cap, stopped when the replayer is done (checked every 5 ms of wall
    // time by a timer on the runner's io_context). Every run_until() re-anchors virtual time to
    // the wall clock, so a run in slices lost the wall time between slices and shrank the
    // program's reply delay in virtual time (seen: TSDR 7 bit times from a program that waits
    // 11; the same fix as the battery's paced waits, conformance/src/test_bus.cpp).
    boost::asio::steady_timer poll(runner.io_context());
    std::function<void(const boost::system::error_code&)> check = [&](const boost::system::error_code& ec) {
      if (ec) return;
      if (rp.finished()) {
        runner.stop();
        return;
      }
      poll.expires_after(std::chrono::milliseconds(5));
      poll.async_wait(check);
    };
    poll.expires_after(std::chrono::milliseconds(5));
    poll.async_wait(check);
    runner.run_until(cap);
    poll.cancel();
    pty->detach_io();
    cf::ReplayCompareOptions co;
    co.masks = ra.masks;
    co.min_tsdr = ra.min_tsdr.value_or(11);
    co.max_tsdr = ra.max_tsdr.value_or(0);
    rc = report(ra, cf::compare_replay(in, rp, co), out);
  }
  ::unlink(ra.pty->c_str());
  return rc;
}

int run_scenario(const ReplayArgs& ra, const std::vector<std::uint8_t>& data, std::ostream& out,
                 std::ostream& err) {
  LoadResult loaded = load_scenario_file(*ra.scenario);
  if (!loaded.ok()) {
    for (const auto& d : loaded.errors) err << d.str() << "\n";
    return 2;
  }
  ScenarioPlan plan = std::move(*loaded.plan);
  if (!plan.redundant_systems.empty() || !plan.h_systems.empty() || !plan.gateways.empty()) {
    err << "pbvbus replay: " << plan.file
        << ": scenarios with redundant master systems, H-systems or gateways cannot be a replay "
           "target\n";
    return 2;
  }
  // The capture's line: by --line, else the first line interface; it must be a scenario line.
  std::string e;
  cf::ReplayInputOptions io;
  io.line = ra.line;
  auto probe = cf::build_replay_input(data, io, e);
  if (!probe) {
    err << "pbvbus replay: " << ra.capture << ": " << e << "\n";
    return 2;
  }
  const PlanLine* pl = nullptr;
  for (const auto& l : plan.lines)
    if (l.name == probe->line) pl = &l;
  if (pl == nullptr) {
    err << "pbvbus replay: the capture's line '" << probe->line << "' is not a line of "
        << plan.file << "\n";
    return 2;
  }
  if (pl->baud != probe->baud) {
    err << "pbvbus replay: line " << pl->name << " runs at " << bus::baud_name(pl->baud)
        << " in the scenario, at " << bus::baud_name(probe->baud) << " in the capture\n";
    return 2;
  }
  io.line = probe->line;
  io.tsl = pl->params.tsl;
  auto in = cf::build_replay_input(data, io, e);
  if (!in) {
    err << "pbvbus replay: " << ra.capture << ": " << e << "\n";
    return 2;
  }
  if (ra.station && pl->position_of(*ra.station) < 0) {
    err << "pbvbus replay: station " << int(*ra.station) << " is not on line " << pl->name << "\n";
    return 2;
  }
  for (const auto& [addr, name] : ra.mutants) {
    bool found = false;
    for (auto& s : plan.dp_slaves)
      if (s.address == addr && plan.lines.at(static_cast<std::size_t>(s.line)).name == pl->name) {
        found = true;
        if (std::string why = set_slave_mutant(s, name); !why.empty()) {
          err << "pbvbus replay: --mutant " << int(addr) << ":" << name << ": " << why << "\n";
          return 2;
        }
      }
    if (!found) {
      err << "pbvbus replay: --mutant: no DP slave " << int(addr) << " on line " << pl->name << "\n";
      return 2;
    }
  }
  cf::Replayer rp(*in, {ra.pacing, ra.station});
  SimulationOptions so;
  so.omit_masters = true;
  so.extra_device = &rp;
  so.extra_line = pl->name;
  std::unique_ptr<Simulation> sim;
  try {
    sim = std::make_unique<Simulation>(plan, so);
  } catch (const std::exception& ex) {
    err << "pbvbus replay: " << ex.what() << "\n";
    return 2;
  }
  sim->start();
  const bus::Ticks cap = time_cap(*in, rp);
  const bus::Ticks slice = 10 * bus::kTicksPerMs;
  while (!rp.finished() && sim->scheduler().now() < cap) {
    sim->run_until(sim->scheduler().now() + slice);
    if (sim->has_external_attachments()) sim->poll_serial();
  }
  cf::ReplayCompareOptions co;
  co.masks = ra.masks;
  co.min_tsdr = ra.min_tsdr.value_or(pl->params.min_tsdr);
  co.max_tsdr = ra.max_tsdr.value_or(pl->params.max_tsdr);
  return report(ra, cf::compare_replay(*in, rp, co), out);
}

}  // namespace

int cmd_replay(const Args& args, std::ostream& out, std::ostream& err) {
  ReplayArgs ra;
  if (std::string e = parse_args(args, ra); !e.empty()) {
    err << "pbvbus replay: " << e << "\n" << kReplayUsage;
    return 2;
  }
  if (ra.help) {
    out << kReplayUsage;
    return 0;
  }
  std::string e;
  auto data = read_file(ra.capture, e);
  if (!data) {
    err << "pbvbus replay: " << e << "\n";
    return 2;
  }
  if (ra.to) return run_to(ra, *data, out, err);
  if (ra.scenario) return run_scenario(ra, *data, out, err);
  cf::ReplayInputOptions io;
  io.line = ra.line;
  auto in = cf::build_replay_input(*data, io, e);
  if (!in) {
    err << "pbvbus replay: " << ra.capture << ": " << e << "\n";
    return 2;
  }
  return run_pty(ra, *in, out, err);
}

}  // namespace pbvbus::tools
