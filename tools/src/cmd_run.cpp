// `pbvbus run [SCENARIO] [options]` (design.md "Configuration and command line").
//
// Decisions:
//  - Without a scenario file the built-in default runs (scenario.hpp default_scenario_text()).
//  - The fast driver is the default unless something outside the process is attached (a pty):
//    then virtual time must follow the wall clock and --paced is the default. --fast with a pty
//    is allowed (the external side then sees a very fast bus) but warned about.
//  - `--capture -` streams pcapng to stdout; the report then goes to stderr, and --json (which
//    would also need stdout) is refused.
//  - `--probe first|last|ADDR` places the capture's probe on lines the scenario gives no
//    `capture` entry (capture_probes.hpp); it needs --capture, and ADDR must be a station of
//    every such line (exit 2 otherwise).
//  - --quiet turns off the progress line only (README "Long runs on a terminal show a progress
//    line"): the report, warnings, the pty paths and the doors' addresses still print, since a
//    script that asks for no progress still wants the result and where to connect.
//  - A paced run without a duration (none in the scenario, no --duration) runs until SIGINT or
//    SIGTERM; either signal ends any run early, and the report covers the time run so far.
//  - Progress (virtual time, speed ratio, frames, error frames) goes to stderr only when stderr
//    is a terminal, --quiet is not given, and the run has taken more than a second of wall
//    time; it is erased before the report.
//  - A scenario with a gateway, an s7_door or a Quantum pair's Modbus port runs paced (its doors
//    face programs in real time);
//    --fast with an s7_door leaves the door closed (its report says "not open"); with a gateway --fast is
//    refused for it. The doors print where they listen (the port an ephemeral one got); a door
//    that cannot open ends the run with exit 1 before it starts.
//  - With --json, a run that cannot start (a bad scenario, a door's port in use, a link path
//    that is a regular file, ...) still prints one JSON object on stdout, besides the usual
//    text on stderr: {"schema":"pbvbus.run.error/1","error":TEXT,"exit_code":N}. A program
//    that parses stdout then learns why instead of finding nothing. Bad usage (an unknown
//    option, --help) is not a run: text only.
//  - Exit codes: 0 done, 1 the run failed (capture could not be written, a gateway's door could
//    not open), 2 bad usage or a bad scenario.

#include <unistd.h>

#include <boost/asio/signal_set.hpp>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstring>
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/tools/class2_cli.hpp"
#include "pbvbus/tools/commands.hpp"
#include "pbvbus/reports/json_text.hpp"
#include "pbvbus/reports/run_report.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/report.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {

namespace {

constexpr const char* kRunUsage =
    "usage: pbvbus run [SCENARIO] [options]\n"
    "\n"
    "Runs a scenario (Protocol Buffers text format, see scenario/proto/scenario.proto); without\n"
    "SCENARIO, a built-in default scenario.\n"
    "\n"
    "options:\n"
    "  --fast            run as fast as possible (default without serial attachments and\n"
    "                    gateways; refused with a gateway)\n"
    "  --paced           virtual time follows the wall clock (default with serial attachments\n"
    "                    or gateways)\n"
    "  --duration T      how long to run, e.g. 500ms, 5s, 2min (overrides the scenario);\n"
    "                    a paced run without any duration runs until interrupted\n"
    "  --seed N          seed of the random choices (overrides the scenario)\n"
    "  --speed N[/M]     paced runs: virtual time runs N/M times as fast as the wall clock\n"
    "                    (e.g. 1/1000 to let a program behind a pty answer within TSDR)\n"
    "  --capture FILE    write a pcapng capture; '-' streams it to stdout\n"
    "  --probe WHERE     where the capture listens on lines without a capture entry in the\n"
    "                    scenario: first (default), last, or next to station ADDR\n"
    "  --json            print the report as JSON (schema pbvbus.run.report/1); a run that\n"
    "                    cannot start prints {\"schema\":\"pbvbus.run.error/1\",\"error\":...}\n"
    "  --quiet, -q       no progress line on the terminal (the report still prints)\n"
    "  -h, --help        this text\n";

/// The --json answer of a run that could not start (schema pbvbus.run.error/1).
void write_json_error(std::ostream& out, const std::string& error, int exit_code) {
  out << "{\"schema\":\"pbvbus.run.error/1\",\"error\":" << json_quote(error)
      << ",\"exit_code\":" << exit_code << "}\n";
}

/// "N" or "N/M", positive integers.
std::optional<bus::Speed> parse_speed(const std::string& v) {
  auto num = [](std::string_view t) -> std::optional<std::uint32_t> {
    std::uint32_t x = 0;
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), x);
    if (ec != std::errc() || p != t.data() + t.size() || x == 0) return std::nullopt;
    return x;
  };
  const auto slash = v.find('/');
  auto n = num(std::string_view(v).substr(0, slash));
  auto d = slash == std::string::npos ? std::optional<std::uint32_t>(1)
                                      : num(std::string_view(v).substr(slash + 1));
  if (!n || !d) return std::nullopt;
  return bus::Speed{*n, *d};
}

struct RunArgs {
  std::optional<std::string> scenario;
  bool fast = false;
  bool paced = false;
  std::optional<bus::Ticks> duration;
  std::optional<std::uint64_t> seed;
  std::optional<std::string> capture;
  std::optional<ProbeDefault> probe;
  std::optional<bus::Speed> speed;
  bool json = false;
  bool quiet = false;
  bool help = false;
  Class2Options dp2;
};

/// Parses the arguments; on error returns the message (without the "pbvbus run: " prefix).
std::optional<std::string> parse_args(const Args& args, RunArgs& out) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* opt) -> std::optional<std::string> {
      if (i + 1 >= args.size()) return std::nullopt;
      (void)opt;
      return args[++i];
    };
    std::string c2_error;
    const Class2ArgResult c2 = parse_class2_arg(args, i, out.dp2, c2_error);
    if (c2 == Class2ArgResult::Error) return c2_error;
    if (c2 == Class2ArgResult::Taken) continue;
    if (a == "-h" || a == "--help") {
      out.help = true;
    } else if (a == "--fast") {
      out.fast = true;
    } else if (a == "--paced") {
      out.paced = true;
    } else if (a == "--json") {
      out.json = true;
    } else if (a == "--quiet" || a == "-q") {
      out.quiet = true;
    } else if (a == "--duration") {
      auto v = value("--duration");
      if (!v) return "--duration needs a value, e.g. --duration 5s";
      auto t = bus::parse_duration(*v);
      if (!t || *t == 0)
        return "bad duration '" + *v + "' (expected a number and a unit: ns, us, ms, s, min, h)";
      out.duration = *t;
    } else if (a == "--seed") {
      auto v = value("--seed");
      if (!v) return "--seed needs a value";
      std::uint64_t s = 0;
      std::size_t used = 0;
      try {
        if (v->empty() || (*v)[0] == '-') throw std::invalid_argument("negative");
        s = std::stoull(*v, &used, 0);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != v->size()) return "bad seed '" + *v + "' (expected an unsigned integer)";
      out.seed = s;
    } else if (a == "--speed") {
      auto v = value("--speed");
      if (!v) return "--speed needs a value, e.g. --speed 1/1000";
      auto sp = parse_speed(*v);
      if (!sp) return "bad speed '" + *v + "' (expected N or N/M with positive integers)";
      out.speed = *sp;
    } else if (a == "--capture") {
      auto v = value("--capture");
      if (!v || v->empty()) return "--capture needs a file name or '-'";
      out.capture = *v;
    } else if (a == "--probe") {
      auto v = value("--probe");
      if (!v) return "--probe needs a value: first, last or a station address";
      out.probe = parse_probe_default(*v);
      if (!out.probe) return "bad probe '" + *v + "' (expected first, last or an address 0..126)";
    } else if (a.size() > 1 && a[0] == '-') {
      return "unknown option '" + a + "'";
    } else if (!out.scenario) {
      out.scenario = a;
    } else {
      return "more than one scenario given ('" + *out.scenario + "' and '" + a + "')";
    }
  }
  if (out.fast && out.paced) return "--fast and --paced exclude each other";
  if (out.probe && !out.capture) return "--probe places the capture's probe; it needs --capture";
  if (out.json && out.capture && *out.capture == "-")
    return "--json and --capture - both need stdout; write the capture to a file";
  return std::nullopt;
}

/// The progress line on a terminal: virtual time, speed ratio, frames and error frames so far
/// (all lines). Redrawn in place at most five times a second, erased before the report.
class Progress {
 public:
  Progress(std::ostream& err, bool enabled, bus::Ticks total, const Simulation& sim)
      : m_err(err), m_enabled(enabled), m_total(total), m_sim(sim),
        m_t0(std::chrono::steady_clock::now()) {}

  void update(bus::Ticks now) {
    if (!m_enabled) return;
    const auto wall = std::chrono::steady_clock::now() - m_t0;
    if (wall < std::chrono::seconds(1) || wall - m_last < std::chrono::milliseconds(200)) return;
    m_last = wall;
    const double w = std::chrono::duration<double>(wall).count();
    const double v = static_cast<double>(now) / bus::kTicksPerSecond;
    std::uint64_t frames = 0, errors = 0;
    for (std::size_t i = 0; i < m_sim.line_count(); ++i) {
      frames += m_sim.stats(i).frames;
      errors += m_sim.stats(i).error_frames();
    }
    char buf[200];
    const std::string total = m_total > 0 ? " / " + bus::format_duration(m_total) : std::string();
    std::snprintf(buf, sizeof buf, "\r%s%s virtual, %.3gx real time, %llu frames, %llu errors   ",
                  bus::format_duration(now).c_str(), total.c_str(), v / w,
                  static_cast<unsigned long long>(frames), static_cast<unsigned long long>(errors));
    m_width = std::max(m_width, std::strlen(buf));
    m_err << buf << std::flush;
    m_shown = true;
  }
  void clear() {
    if (m_shown) m_err << "\r" << std::string(m_width, ' ') << "\r" << std::flush;
  }
  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_t0).count();
  }

 private:
  std::ostream& m_err;
  bool m_enabled;
  bus::Ticks m_total;
  const Simulation& m_sim;
  std::size_t m_width = 0;
  std::chrono::steady_clock::time_point m_t0;
  std::chrono::steady_clock::duration m_last{};
  bool m_shown = false;
};

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_signal(int) { g_interrupted = 1; }

/// Shows progress every 100 ms of virtual time during a paced run (run_until blocks).
class ProgressTick final : public bus::EventTarget {
 public:
  ProgressTick(bus::Scheduler& s, Progress& p) : m_sched(s), m_progress(p) {}
  void arm() { m_sched.schedule(m_sched.now() + 100 * bus::kTicksPerMs, *this); }
  void on_event(bus::Ticks now, std::uint64_t) override {
    m_progress.update(now);
    arm();
  }

 private:
  bus::Scheduler& m_sched;
  Progress& m_progress;
};

}  // namespace

int cmd_run(const Args& args, std::ostream& out, std::ostream& err) {
  RunArgs ra;
  if (auto e = parse_args(args, ra)) {
    err << "pbvbus run: " << *e << "\n" << "Try 'pbvbus run --help'.\n";
    return 2;
  }
  if (ra.help) {
    out << kRunUsage << kClass2Usage;
    return 0;
  }

  const LoadResult loaded = ra.scenario ? load_scenario_file(*ra.scenario)
                                        : parse_scenario(default_scenario_text(), "<built-in default>");
  // Start-up failures: the text on stderr, and with --json the error object on stdout.
  const auto fail = [&](int rc, const std::string& why) {
    err << "pbvbus run: " << why << "\n";
    if (ra.json) write_json_error(out, why, rc);
    return rc;
  };
  if (!loaded.ok()) {
    std::string all;
    for (const auto& d : loaded.errors) {
      err << d.str() << "\n";
      all += (all.empty() ? "" : "\n") + d.str();
    }
    if (ra.json) write_json_error(out, all, 2);
    return 2;
  }

  const ScenarioPlan& plan = *loaded.plan;
  bool has_serial = false;
  for (const auto& l : plan.lines)
    for (const auto& st : l.stations)
      has_serial |= st.kind == StationKind::SerialMonitor || st.kind == StationKind::SerialStation;
  // Gateways and S7 doors are doors to the outside like a pty: paced by default, and only paced.
  if (!plan.gateways.empty() && ra.fast)
    return fail(2, plan.file + " has a gateway: its doors need a paced run (drop --fast)");
  // An S7 door is not needed to run the plant (no outputs depend on it): a fast run (tests,
  // captures) simply does not open it, and the report says so.
  // A Quantum pair's Modbus ports are doors too (paced by default; --fast leaves them closed, as
  // it does an S7 door: the pair runs the same without a host polling it).
  bool has_quantum_doors = false;
  for (const auto& q : plan.quantum) has_quantum_doors |= !q.modbus.empty();
  const bool paced = ra.paced || (!ra.fast && (has_serial || !plan.gateways.empty() ||
                                               !plan.s7.doors.empty() || has_quantum_doors));
  const std::optional<bus::Ticks> duration = ra.duration ? ra.duration : plan.duration;
  if (!duration && !paced)
    return fail(2, plan.file + ": the scenario has no duration; add duration: \"5s\" or use --duration");
  if (ra.speed && !paced) return fail(2, "--speed applies to paced runs only (add --paced)");

  // With the capture on stdout, everything else goes to stderr.
  const bool capture_stdout = ra.capture && *ra.capture == "-";
  std::ostream& report_os = capture_stdout ? err : out;

  std::unique_ptr<captures::PcapngWriter> capture;
  if (ra.capture) {
    std::string why;
    if (!plan_capture_probes(plan, ra.probe.value_or(ProbeDefault{}), &why)) return fail(2, why);
  }
  if (ra.capture) {
    std::string why;
    capture = captures::PcapngWriter::open(*ra.capture, {}, &why);
    if (!capture) return fail(2, "cannot write the capture " + *ra.capture + ": " + why);
  }

  SimulationOptions so;
  so.duration = duration;
  so.seed = ra.seed;
  so.capture = capture.get();
  so.probe = ra.probe.value_or(ProbeDefault{});
  std::unique_ptr<Simulation> sim;
  try {
    sim = std::make_unique<Simulation>(plan, so);
  } catch (const std::exception& e) {
    return fail(1, e.what());
  }
  std::unique_ptr<Class2Cli> dp2;
  if (!ra.dp2.empty()) {
    std::string why;
    dp2 = Class2Cli::attach(*sim, ra.dp2, why);
    if (!dp2) return fail(2, why);
  }
  // A paced run without a duration goes on until interrupted.
  // (Ten years: far enough, and safe from overflow when the runner scales it to wall time.)
  const bus::Ticks end = duration ? *duration : 10 * 365 * 24 * 3600 * bus::kTicksPerSecond;

  for (const auto& sp : sim->serial_ports()) {
    err << "serial " << sp.mode << " on line " << sp.line << ": " << sp.path;
    if (!sp.link.empty()) err << " (" << sp.link << ")";
    err << "\n";
  }
  if (ra.fast && has_serial)
    err << "pbvbus run: warning: --fast with serial attachments: the bus runs faster than real "
           "time\n";

  const bool show_progress = !ra.quiet && &err == &std::cerr && ::isatty(STDERR_FILENO) == 1;
  Progress progress(err, show_progress, duration.value_or(0), *sim);
  g_interrupted = 0;
  sim->start();
  if (paced) {
    // The runner belongs to the simulation (torn down after its doors); the signal set below
    // is the only other user of its io_context and goes at the end of this block.
    bus::PacedRunner* runner_ptr = nullptr;
    try {
      runner_ptr = &sim->paced_runner(ra.speed.value_or(bus::Speed{}));
    } catch (const std::exception& e) {
      return fail(1, e.what());
    }
    bus::PacedRunner& runner = *runner_ptr;
    for (std::size_t i = 0; i < sim->gateway_count(); ++i)
      for (const std::string& line : sim->gateway(i).door_lines()) err << line << "\n";
    for (std::size_t i = 0; i < sim->quantum_count(); ++i)
      for (const std::string& line : sim->quantum(i).door_lines()) err << line << "\n";
    boost::asio::signal_set signals(runner.io_context(), SIGINT, SIGTERM);
    signals.async_wait([&runner](const boost::system::error_code& ec, int) {
      if (!ec) {
        g_interrupted = 1;
        runner.stop();
      }
    });
    // Said only once SIGINT is handled, so that whoever waits for it may send one.
    if (!duration) err << "pbvbus run: running until interrupted (Ctrl-C)\n";
    ProgressTick tick(sim->scheduler(), progress);
    tick.arm();
    runner.run_until(end);
    signals.cancel();
  } else {
    // Ctrl-C ends a fast run at the next slice, with a report.
    auto old_int = std::signal(SIGINT, on_signal);
    auto old_term = std::signal(SIGTERM, on_signal);
    // Slices let progress show and ptys be read; they do not change the result.
    const bus::Ticks slice = 10 * bus::kTicksPerMs;
    for (bus::Ticks t = sim->scheduler().now(); t < end && !g_interrupted;) {
      t = std::min(end, t + slice);
      if (has_serial) sim->poll_serial();
      sim->run_until(t);
      progress.update(t);
    }
    std::signal(SIGINT, old_int);
    std::signal(SIGTERM, old_term);
  }
  progress.clear();
  const double wall = progress.elapsed();
  if (g_interrupted)
    err << "pbvbus run: interrupted at " << bus::format_duration(sim->scheduler().now()) << "\n";

  int rc = 0;
  if (capture) {
    capture->flush();
    if (!capture->ok()) {
      err << "pbvbus run: writing the capture failed: " << capture->error() << "\n";
      rc = 1;
    }
  }
  const Report report = sim->report(wall);
  if (ra.json) {
    std::ostringstream js;
    write_json(report, js);
    std::string j = js.str();
    if (dp2) dp2->add_to_json(j);
    out << j;
  } else {
    write_text(report, report_os);
    if (dp2) dp2->write_text(report_os);
  }
  return rc;
}

}  // namespace pbvbus::tools
