#pragma once
// Configured S7 connections of an H-system over its CPs (docs/h-system.md; seeds-digest.md §7 F4, §11 R8;
// 000 §7.1 "fault-tolerant S7 connections", §9.1.4 "failure and replacement of a communication
// processor"; docs/h-system.md "Connections and CPs (F4, R8)").
//
// Sans-I/O, driven by the pair's state: the owner calls update(pair, now) after every operation
// and deadline of the HCpuPair (HSystemModel does it in reconcile()), and fail_cp / repair_cp /
// reestablish at a virtual time. No clock, no threads.
//
// Rules and decisions:
// - Each CPU has CPs (CP 443-1 Industrial Ethernet, CP 443-5 PROFIBUS), indexed per rack. A CP
//   lives in its CPU's rack: it carries nothing while its CPU does not.
// - A CPU *carries* connections while it is powered and not in ERROR-SEARCH or DEFECTIVE, except
//   the standby in LINK-UP/UPDATE (R8: link-up breaks all the standby's connections, the
//   master keeps its own). A CPU in STOP keeps its connections (an S7 connection to a CPU in
//   STOP stays; the seeds say nothing else); a new one needs the CPU in RUN and
//   HCpuPair::accepts_connections() (R8: none on either CPU from the start of a link-up to the
//   end of the update; none on a CPU that is off/ERROR-SEARCH/DEFECTIVE). accepts_connections
//   is the pair's one rule: HCpuPair::connect() (its counter of unconfigured connections, the
//   R8 tests) uses it too, so there are not two admission rules. The pair's counter and this
//   class count different things (ad-hoc vs configured connections) and never each other's.
// - A configured connection starts Configured and is established by the system at the first
//   update() that allows it (its CP up, its CPU in RUN and accepting).
// - Standard connection (one CPU, one CP): lost when its CP fails, its CPU stops carrying
//   (off, ERROR-SEARCH, DEFECTIVE) or its CPU is the standby at link-up (R8). A lost standard
//   connection does NOT come back by itself: the partner (the active end of the configured
//   connection) re-establishes it with reestablish(); after a CP replacement the owner does
//   so at the repair (000 §9.1.4 step 3: "the system establishes the connection
//   automatically"; HSystemModel::repair_cp does it).
// - Fault-tolerant connection: one partial connection (path) per CP of the connection's CP kind
//   on both CPUs (the same count on each: 2 paths with one CP per CPU, 4 with two; 000 §7.1:
//   "up to four partial connections"). One path is active (carries the data), every other
//   usable one is a reserve, established beforehand (000 §7.1: "a previously established second
//   partial connection assumes responsibility"). The first active path is (the master's rack,
//   `cp`). When the active path goes down the connection switches: the same CPU's other CP
//   first (ascending index), else the partner's (its CP with the same index first, then
//   ascending); lost only when no path remains. A path comes back (CP repaired, CPU back in
//   RUN after its update) as a reserve only: the active path stays (no switch back). A lost
//   fault-tolerant connection, like a standard one, needs reestablish().
// - Events with the virtual time (CP failed/repaired, established, path switched, path lost,
//   path regained, lost) for the report and the diagnostic buffers (both CPUs log, 000 §9.1.4).
//   No OB is raised: the seeds say "appropriate OBs" without naming one for a CP failure.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {

enum class CpKind : std::uint8_t { Cp443_1, Cp443_5 };
std::string_view to_string(CpKind k);  ///< "CP 443-1" / "CP 443-5"

enum class ConnectionKind : std::uint8_t { Standard, FaultTolerant };
std::string_view to_string(ConnectionKind k);  ///< "standard" / "fault-tolerant"

enum class ConnectionState : std::uint8_t { Configured, Established, Lost };
std::string_view to_string(ConnectionState s);  ///< "configured" / "established" / "lost"

struct CpConfig {
  int rack = 0;   ///< 0 or 1
  int index = 0;  ///< per rack, >= 0, unique in the rack
  CpKind kind = CpKind::Cp443_1;
};

struct ConnectionConfig {
  std::string name;  ///< unique, not empty
  ConnectionKind kind = ConnectionKind::Standard;
  int rack = 0;  ///< Standard only: the CPU
  int cp = 0;    ///< the CP index (Standard: on `rack`; fault-tolerant: the first active path's
                 ///< CP on the master's rack; its kind selects the paths)
};

struct ConnectionPath {
  int rack = 0;
  int cp = 0;
  bool up = false;  ///< the partial connection exists (active or reserve)
};

struct Connection {
  ConnectionConfig config;
  ConnectionState state = ConnectionState::Configured;
  std::vector<ConnectionPath> paths;  ///< Standard: one; fault-tolerant: rack 0's CPs, rack 1's
  int active = -1;                    ///< index into paths, -1 unless Established
  bus::Ticks lost_at = bus::kNever;
};

struct CommEvent {
  enum class Kind : std::uint8_t {
    CpFailed,
    CpRepaired,
    Established,
    Reestablished,
    PathSwitched,  ///< fault-tolerant: the active path moved (rack/cp -> to_rack/to_cp)
    PathLost,      ///< fault-tolerant: a reserve path went down
    PathRegained,  ///< fault-tolerant: a path is back as a reserve
    Lost,
  };
  bus::Ticks at = 0;
  Kind kind = Kind::CpFailed;
  int connection = -1;  ///< index, -1 for CP events
  int rack = -1, cp = -1;
  int to_rack = -1, to_cp = -1;  ///< PathSwitched
  std::string text;
};
std::string_view to_string(CommEvent::Kind k);

class HConnections {
 public:
  /// Configuration (before the run). Return "" or an error text; nothing changes on an error.
  std::string add_cp(const CpConfig& cp);
  std::string add_connection(const ConnectionConfig& c);

  /// The CP fails (F4) / is replaced. false: no such CP, or already failed / not failed.
  bool fail_cp(int rack, int cp, const HCpuPair& pair, bus::Ticks now);
  bool repair_cp(int rack, int cp, const HCpuPair& pair, bus::Ticks now);
  /// The partner re-establishes a lost connection (every path that can be set up now).
  /// false: no such connection, not lost, or no path can be set up now (R8 etc.).
  bool reestablish(std::size_t connection, const HCpuPair& pair, bus::Ticks now);
  /// Follows the pair: losses, switches, first establishment, regained paths.
  void update(const HCpuPair& pair, bus::Ticks now);

  const std::vector<CpConfig>& cps() const { return m_cps; }
  bool cp_ok(int rack, int cp) const;
  const std::vector<Connection>& connections() const { return m_conns; }
  /// Index of the connection named `name`, -1 if none.
  int find(std::string_view name) const;
  const std::vector<CommEvent>& events() const { return m_events; }

 private:
  int cp_slot(int rack, int cp) const;  ///< index into m_cps, -1
  static bool carries(const HCpuPair& pair, int rack);
  bool keep(const HCpuPair& pair, const ConnectionPath& p) const;
  bool can_establish(const HCpuPair& pair, const ConnectionPath& p) const;
  std::string why_down(const HCpuPair& pair, const ConnectionPath& p) const;
  std::string path_name(const ConnectionPath& p) const;
  /// The next active path after `from` (fault-tolerant order), -1 if none is up.
  int next_path(const Connection& c, int from) const;
  /// Sets up every path that can be; the active one by preference. true if one is up.
  bool establish(std::size_t i, const HCpuPair& pair, bus::Ticks now, CommEvent::Kind kind);
  void update_one(std::size_t i, const HCpuPair& pair, bus::Ticks now);
  void emit(CommEvent e) { m_events.push_back(std::move(e)); }

  std::vector<CpConfig> m_cps;
  std::vector<bool> m_cp_failed;
  std::vector<Connection> m_conns;
  std::vector<CommEvent> m_events;
};

}  // namespace pbvbus::devices
