// The scenario `pbvbus run` runs without a file. It must run unattended and end by itself: no
// serial attachment, a fixed duration. It is examples/h-system.textproto (the seeds' story: a
// CPU pair powering up to Redundant, F5, an IM failure, F1 and the return of the failed CPU),
// word for word except for the GSD paths (tests/scenario/default_scenario_test.cpp keeps the two
// equal).
//
// GSD paths: the built-in scenario has no file to be relative to, so "@EXAMPLES@" stands for
// the source tree's examples/ folder, compiled in as PBVBUS_EXAMPLES_DIR. A binary moved away
// from its source tree then reports the missing GSD file like any scenario would.
#include <string>

#include "pbvbus/scenario/scenario.hpp"

#ifndef PBVBUS_EXAMPLES_DIR
#define PBVBUS_EXAMPLES_DIR "examples"
#endif

namespace pbvbus::tools {

namespace {
constexpr char kDefault[] = R"pb(# pbvbus scenario: an S7-400H-style H-system, the seeds' story (docs/h-scenarios.md).
#
# A CPU pair (rack 0 and rack 1, sync link of two fibres) drives one redundant DP master system
# "H-DP 1" on two lines at 1.5 Mbit/s: DP_A belongs to rack 0, DP_B to rack 1. Two switched
# stations (ET 200M with two IM 153-2, examples/gsd/PBVB0A10.gsd) and one one-sided slave per
# line (PBVB0A01.gsd). The process images (the report prints the map): station 3 IB 0..1 /
# QB 0..1, station 4 IB 2..3 / QB 2..3, slave 10 IB 4..5 / QB 4..5, slave 11 IB 6..7 / QB 6..7.
# The program: a counter on QB 0..1 (station 3's outputs) with a pulse on Q 2.0 (station 4),
# and a copy of station 3's inputs (IB 0..1) to slave 10's outputs (QB 4..5).
#
# What to expect (`pbvbus run` runs this as its built-in default; the times come from the
# pair's settings below: startup 1 s, link-up 2 s, update W = MAX(75 ms + 0.7 ms x 100 KB,
# 50 ms + T_PH 30 ms) = 145 ms, both CPUs driving the outputs for the last 30 ms of it):
#   0 s      both CPUs power on together (simultaneous POWER ON, rack 0 master): CPU 0 STOP ->
#            STARTUP; CPU 1 waits in STOP (standby).
#   1 s      CPU 0 RUN, system mode Solo; CPU 1 LINK-UP (REDF 0.5 Hz).
#   3 s      CPU 1 UPDATE (REDF 2 Hz); 3.145 s CPU 1 RUN: Redundant (REDF off).
#   5 s      F5: the upper fibre is cut: CPU 1 (standby) STOPs, OB 72 (redundant link lost) on
#            CPU 0, Solo. 6 s the fibre is spliced (a repair starts nothing by itself).
#   6.5 s    CPU 1's mode switch to STOP, 7 s back to RUN: link-up 7 s -> 9 s, update ->
#            9.145 s Redundant.
#   10 s     IM failure: station 3's DP_A interface (F10): OB 70 W#16#73A3, station 3 switches
#            to DP_B. 11 s repaired: W#16#72A3.
#   12 s     F1: the master CPU 0 fails: CPU 1 takes over (master, Solo), OB 72 (master CPU
#            lost); DP_A's master stops with its CPU: one W#16#39C3, all stations on DP_B.
#   14 s     CPU 0's power returns: it is standby, links up by itself (14 s -> 16 s), update ->
#            16.145 s Redundant, now with CPU 1 as master.
#   Also: OB 85 (process-image transfer error, W#16#39B1 / 38B1) at the first OB 1 that finds
#   a one-sided slave of the lost side gone (5.005 s, 12.005 s) and back (9.145 s, 16.145 s).
#   MPI: the OP connects to CPU 0 (MPI 2) and reads every 200 ms; 12 s its connection breaks,
#            16.145 s it is back. The S7 door at 127.0.0.1:10102 (rack 0, slot 3) answers
#            from the master CPU (a paced run: `pbvbus run` paces a scenario with a door).
#   18 s     end.
name: "h-system"
description: "An H-system CPU pair on a redundant DP master system: power-up to Redundant, F5, an IM failure, F1 and the return of the failed CPU."
seed: 8
duration: "18s"

line { name: "DP_A" baud: "1.5M" }
line { name: "DP_B" baud: "1.5M" }
# The CPUs' MPI subnet (187.5 kbit/s, HSA 31): CPU 0 at MPI address 2, CPU 1 at 3, an OP at 1.
line { name: "MPI" kind: MPI }

dp_master { address: 1 line: "DP_A" watchdog: "100ms" }
dp_master { address: 1 line: "DP_B" watchdog: "100ms" }

redundant_master_system {
  name: "H-DP 1"
  line_a: "DP_A"
  master_a: 1
  line_b: "DP_B"
  master_b: 1
  output_hold_time: "1s"
}

switched_station {
  system: "H-DP 1"
  address: 3
  gsd: "@EXAMPLES@/gsd/PBVB0A10.gsd"
  modules: ["16DI DC24V", "16DO DC24V/0.5A"]
}
switched_station {
  system: "H-DP 1"
  address: 4
  gsd: "@EXAMPLES@/gsd/PBVB0A10.gsd"
  modules: ["16DI DC24V", "16DO DC24V/0.5A"]
  inputs: ECHO
}

dp_slave { address: 10 line: "DP_A" gsd: "@EXAMPLES@/gsd/PBVB0A01.gsd" master: 1 }
dp_slave { address: 11 line: "DP_B" gsd: "@EXAMPLES@/gsd/PBVB0A01.gsd" master: 1 }

h_system {
  name: "H-CPU"
  # The DP master system the pair drives (and the T_P15 inputs for `pbvbus timing`).
  dp_system { system: "H-DP 1" t_pto: "1250ms" }
  t_wa: "100ms"
  t_prog: "10ms"
  work_memory_db_kb: 100
  # `pbvbus timing`: T_P15_AWP = 75 + 0.7 x 100 = 145 ms > T_P15_OD = 50 + T_PH 30 = 80 ms, so
  # T_P15 = 145 ms; recommended 4 x 145 = 580 ms and 10 x 145 = 1450 ms. The set passes every
  # check (a simulated pair must not run on a bad set).
  h_parameters {
    max_cycle_extension: "1450ms"
    max_communication_delay: "580ms"
    max_blocking_time: "145ms"
    min_io_hold_time: "30ms"
  }
  cpu {
    profile: S7_400H
    cpu0 { power_on: "0s" switch: RUN }
    cpu1 { power_on: "0s" switch: RUN }
    fibres_connected_at_power_on: true
    startup_time: "1s"
    link_up_time: "2s"
    comparison_reaction: ERROR_SEARCH
    mpi { line: "MPI" }                      # CPU 0 at 2, CPU 1 at 3
    s7_memory { db { number: 1 size: 64 } }  # M from MB 0 is the program's state
  }
  program {
    scan_time: "10ms"
    # QB 0..1: a 16-bit counter, +1 every 100 ms; Q 2.0 high for the first 50 ms of each period.
    counter { output: 0 width: 2 period: "100ms" step: 1 pulse_output: 2 pulse_bit: 0 pulse_high: "50ms" }
    # IB 0..1 (station 3's inputs) -> QB 4..5 (station 4's outputs).
    copy { from_input: 0 to_output: 4 length: 2 }
  }
}

# An OP on the MPI line reads the program's counter (QW 0) and the program's state (its counter
# value is MD 8, docs/h-system.md "S7 communication") from CPU 0 every 200 ms: at 12 s CPU 0
# fails, the OP's connection breaks; it connects again once CPU 0 is back and its update is
# over (no connections during link-up and update, seed R8).
mpi_station { role: OP line: "MPI" read { cpu: 2 item: "QW0" period: "200ms" } read { cpu: 2 item: "MD8" period: "200ms" } }
# S7 clients (nodes7, HMIs) reach the H-system at 127.0.0.1:10102, rack 0 slot 3, on an ad-hoc
# connection to the master CPU (README "MPI and S7"). The door opens in paced runs (the default).
s7_door { name: "S7" listen: "127.0.0.1:10102" route { rack: 0 slot: 3 h_system: "H-CPU" } }

# F5 and its repair; then the standby's STOP -> RUN to link up again.
fault { at: "5s" repair_at: "6s" fibre_cut { fibre: 0 } }
fault { at: "6.5s" repair_at: "7s" cpu_stop { rack: 1 } }
# An IM failure (F10): station 3's DP_A interface.
fault { at: "10s" repair_at: "11s" interface_failure { address: 3 line: "DP_A" } }
# F1: the master CPU fails; its power returns at 14 s.
fault { at: "12s" repair_at: "14s" cpu_failure { rack: 0 } }
)pb";
}  // namespace

std::string_view default_scenario_text() {
  static const std::string text = [] {
    std::string t = kDefault;
    const std::string key = "@EXAMPLES@";
    for (std::size_t p; (p = t.find(key)) != std::string::npos;) t.replace(p, key.size(), PBVBUS_EXAMPLES_DIR);
    return t;
  }();
  return text;
}

}  // namespace pbvbus::tools
