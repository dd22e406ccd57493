#pragma once
// S7 communication in scenarios (scenario/proto/scenario.proto messages S7Cpu, MpiStation,
// S7Door, HMpi; docs/mpi.md, docs/s7cpu.md, docs/iso-on-tcp.md): the loader's checked form of
// the single CPUs, the PGs and OPs, the H CPUs' MPI interfaces and the S7 doors.
//
// Decisions (the loader reports each violation with FILE:LINE:COLUMN):
//  - A line of kind MPI runs at 187.5 kbit/s unless it names a baud (protocol-facts.md §H.1),
//    with the MPI bus parameters (mpi_station::mpi_bus_params: HSA 31, docs/mpi.md "MPI bus
//    parameters") under its own bus_params. It carries
//    no DP: a dp_master, dp_slave or switched station on it is an error (a CPU's MPI/DP
//    interface is either MPI or DP, as on the real module). Plain masters, passive stations
//    and serial attachments are allowed (an outside PG joins through a serial STATION).
//  - MPI stations (a CPU's MPI interface, each H CPU's, a PG, an OP, a door's own station) are
//    active stations: their address must be at most the line's HSA, or no GAP poll would ever
//    let them into the token ring. Defaults: CPU 2, PG 0, OP 1 (§H.1), H CPUs 2 and 3, the
//    door's station the lowest address nobody else uses on its line.
//  - A single CPU has X1 (mode MPI or DP) and optionally X2 (DP only). In DP mode the
//    interface IS a dp_master entry: `line` + `address` must name one, of no other CPU, on a
//    PROFIBUS-DP line. At least one interface. DB numbers 1..65535 unique, sizes 1..65534;
//    I, Q, M sizes up to 16 384 (the largest S7-400 process image); max_connections 1..64
//    (default 12: an S7-300 CPU's S7 connection resources). A `program` is checked like an
//    h_system's (plan_program_spec) and against the CPU's I/Q sizes (devices::validate).
//  - Every h_system with a `cpu` part serves S7 (its memory: cpu.s7_memory, flags default 256,
//    DBs as a single CPU's); an H pair's MPI addresses differ (the only thing in which CPU 1 may differ from CPU 0,
//    seeds-digest.md §3.2); max_connections 1..64, default 44 (a 417-4H's MPI resources, the profile's CPU).
//  - A PG/OP read names the MPI address of a CPU on the station's own line, an item in S7
//    syntax (s7_item below) and a period > 0 (default 100 ms).
//  - S7 doors: names unique, "HOST:PORT" as the gateways' (numeric host; a port other than 0
//    only once in the file, across gateways and doors); at least one route; (rack, slot)
//    unique in a door, rack 0..7, slot 0..31; a route names an s7_cpu, an h_system with a
//    `cpu` part (and optionally one of its configured connections), or the MPI address of a
//    CPU on the door's `mpi_line` (then required, of kind MPI). idle_timeout > 0, default 60 s.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/s7h/h_program_spec.hpp"
#include "pbvbus/s7h/h_s7_memory.hpp"
#include "pbvbus/scenario/gateway_plan.hpp"

namespace pbvbus::tools {

struct Diagnostic;
struct ScenarioPlan;

/// One S7 item in S7 syntax: "DB1.DBW2", "MB10", "IB0", "QD4", "DB5.DBB0,10".
struct S7ItemPlan {
  enum class Area : std::uint8_t { Db, Inputs, Outputs, Flags };
  Area area = Area::Db;
  std::uint16_t db = 0;        ///< Area::Db only
  std::uint32_t byte = 0;      ///< start byte
  std::uint8_t width = 1;      ///< 1 (B), 2 (W), 4 (D)
  std::uint16_t count = 1;     ///< elements
  std::uint32_t bytes() const { return static_cast<std::uint32_t>(width) * count; }
  std::string str() const;     ///< canonical text, e.g. "DB1.DBW2" or "MB0,4"
};
/// Parses an item (above); the error text says what is wrong, or "" with `out` set.
std::string parse_s7_item(const std::string& text, S7ItemPlan& out);

struct S7DbPlan {
  std::uint16_t number = 0;
  std::uint32_t size = 0;
};

/// A CPU's DP interface: the dp_master entry it is.
struct CpuDpPlan {
  int line = -1;
  std::uint8_t address = 0;
  int dp_master = -1;  ///< index into ScenarioPlan::dp_masters
};

struct S7CpuPlan {
  int source = 0;  ///< index into Scenario.s7_cpu
  std::string name;
  std::string order_number;
  int mpi_line = -1;  ///< X1 in MPI mode: the line, else -1
  std::uint8_t mpi_address = 2;
  std::optional<CpuDpPlan> x1_dp;  ///< X1 in DP mode
  std::optional<CpuDpPlan> x2_dp;  ///< X2
  std::vector<S7DbPlan> dbs;
  std::uint32_t input_bytes = 128, output_bytes = 128, flag_bytes = 256;
  std::uint32_t max_connections = 12;
  bool run = true;
  std::optional<devices::ProgramSpec> program;  ///< `program` (checked against I/Q sizes)
};

/// What S7 clients see of an h_system's CPUs (set whenever the h_system has a `cpu` part).
struct HS7Plan {
  int h_system = -1;  ///< index into ScenarioPlan::h_systems
  devices::HS7MemoryConfig memory;
};

/// The MPI interfaces of an h_system's CPUs.
struct HMpiPlan {
  int h_system = -1;  ///< index into ScenarioPlan::h_systems
  int line = -1;
  std::uint8_t address[2] = {2, 3};
  std::uint32_t max_connections = 44;
};

struct S7PollPlan {
  std::uint8_t cpu = 2;  ///< the CPU's MPI address on the station's line
  S7ItemPlan item;
  bus::Ticks period = 100 * bus::kTicksPerMs;
};

struct MpiStationPlan {
  int source = 0;  ///< index into Scenario.mpi_station
  bool op = false;  ///< role OP (else PG)
  int line = -1;
  std::uint8_t address = 0;
  std::vector<S7PollPlan> reads;
};

struct S7RoutePlan {
  enum class Kind : std::uint8_t { Cpu, HSystem, Mpi };
  std::uint8_t rack = 0, slot = 0;
  Kind kind = Kind::Cpu;
  int target = -1;       ///< Cpu: index into s7_cpus; HSystem: into h_systems
  int connection = -1;   ///< HSystem: index into its runtime's connections, -1 = ad hoc
  std::uint8_t mpi_address = 0;  ///< Mpi: the CPU's address on the door's MPI line
};

struct S7DoorPlan {
  int source = 0;  ///< index into Scenario.s7_door
  std::string name;
  GwEndpoint listen{"127.0.0.1", 10102};
  std::uint32_t max_connections = 0;  ///< 0 = the door's default
  bus::Ticks idle_timeout = 60 * bus::kTicksPerSecond;
  int mpi_line = -1;
  std::uint8_t mpi_address = 0;  ///< the door's own MPI station (mpi_line >= 0)
  std::vector<S7RoutePlan> routes;
};

/// Everything S7 in a scenario.
struct S7Plan {
  std::vector<S7CpuPlan> cpus;
  std::vector<HMpiPlan> h_mpi;
  std::vector<HS7Plan> h_memory;
  std::vector<MpiStationPlan> stations;
  std::vector<S7DoorPlan> doors;
  /// The S7 CPUs on MPI line `line`: (address, "CPU name" or "h_system rack r").
  std::vector<std::pair<std::uint8_t, std::string>> cpus_on(int line) const;
};

/// A field inside Scenario.<repeated>[index]: path of (field, element) steps as HLocator.
using S7Locator = std::function<std::pair<int, int>(const char* repeated, int index,
                                                    const std::vector<std::pair<const char*, int>>& path)>;

/// Plans the S7 entries (after the stations, the dp masters, the h_systems and the gateways:
/// it refers to all of them).
void plan_s7(ScenarioPlan& plan, const S7Locator& locate, std::vector<Diagnostic>& errors);

}  // namespace pbvbus::tools
