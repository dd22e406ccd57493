#pragma once
// The runtime nodes of S7 communication (scenario/include/pbvbus/scenario/s7_plan.hpp): a
// single S7 CPU (its memory, its MPI interface, its DP interfaces) and a PG/OP that reads items
// from CPUs over MPI. docs/s7cpu.md "A single CPU in a scenario" and docs/mpi.md "PGs and OPs in
// a scenario" have the decisions.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/mpi_station/mpi_station.hpp"
#include "pbvbus/mpi_station/s7cpu_sessions.hpp"
#include "pbvbus/s7cpu/cpu_memory.hpp"
#include "pbvbus/s7cpu/s7_server.hpp"
#include "pbvbus/s7h/h_program.hpp"
#include "pbvbus/s7h/h_system.hpp"
#include "pbvbus/scenario/s7_plan.hpp"

namespace pbvbus::tools {

/// A single S7-300/400-style CPU.
///
/// Decisions:
/// - Its memory is an s7cpu::CpuMemory with the planned I/Q/M sizes and DBs (all zero at
///   the start of the run). With a `program`, I, Q and M are views of a devices::ProcessImage
///   (PII, PIQ, and the program's state from MB 0 followed by the free flags) and OB 1 runs
///   every scan_time as one event (devices::Program::scan): what the program writes is what a
///   client reads, and a client's write is what the next OB 1 sees. Without a program, what
///   clients write to Q goes to the slaves, what the slaves send is read from I.
/// - DP interfaces: at every token receipt of the interface's DP master (one DP cycle) the
///   master's slaves' inputs are copied into I and Q is copied to their outputs. The I/O
///   addresses are assigned as a configuration tool would with no addresses given: the master's
///   slaves in ascending address order, their modules in slot order, each module's inputs at the
///   next free input byte and its outputs at the next free output byte, X1's slaves first, then
///   X2's. Bytes that do not fit the image are not exchanged (the report says how many).
/// - The program's DP system functions (docs/h-dp-sfc.md): SFC 14/15 run inside
///   devices::Program on the modules' addresses given by attach_dp(); SFC 11/12 run after each
///   OB 1 (s7_dp_sfc.cpp) on the DP master of the interface named by `line`.
/// - In STOP the CPU keeps answering S7 (SZL 0424 says STOP) and its DP masters write zero
///   outputs (the outputs of a CPU in STOP are disabled).
class S7CpuNode final : public bus::EventTarget {
 public:
  /// `mpi_params`: the MPI line's bus parameters when X1 is on MPI.
  S7CpuNode(bus::Scheduler& sched, const S7CpuPlan& plan, const fdl::BusParams* mpi_params);
  /// Starts OB 1 (with a program, in RUN) at `now`.
  void start(bus::Ticks now);
  void on_event(bus::Ticks now, std::uint64_t tag) override;
  std::uint64_t scans() const { return m_scans; }

  const S7CpuPlan& plan() const { return m_plan; }
  s7cpu::CpuMemory& memory() { return m_memory; }
  const s7cpu::CpuInfo& info() const { return m_info; }
  /// X1's MPI station (nullptr when X1 is a DP interface).
  mpi_station::MpiStation* mpi() { return m_mpi.get(); }
  const mpi_station::MpiStation* mpi() const { return m_mpi.get(); }
  /// Sessions for the ISO-on-TCP door (PDU size up to 960, as a CP offers).
  std::unique_ptr<s7cpu::S7Server> open_server();

  /// One DP cycle of the interface driven by `master` (called from its token receipt).
  void exchange(dp::Master& master);
  /// The DP interface on `line` is driven by `master` (X1 when `x1`): its modules get their
  /// addresses now (X1's first), SFC 14/15 find them, SFC 11/12 act on `master`.
  void attach_dp(const std::string& line, dp::Master& master, bool x1);

  /// One SFC 11/12 call of the program as it ran (docs/h-dp-sfc.md).
  struct DpSfcRecord {
    bus::Ticks time = 0;
    int sfc = 0;  ///< 11 or 12
    std::size_t call = 0;  ///< index in the spec's dpsyc_fr / d_act_dp
    std::uint16_t ret_val = 0;
  };
  const std::vector<DpSfcRecord>& dp_sfc_calls() const { return m_dp_sfc; }

  std::uint64_t dp_exchanges() const { return m_exchanges; }
  std::uint32_t unmapped_bytes() const { return m_unmapped; }

 private:
  struct Slot {
    std::uint8_t slave = 0;
    std::size_t module = 0;
    std::uint32_t in_at = 0, in_len = 0, out_at = 0, out_len = 0;
  };
  void map(dp::Master& master);

  bus::Scheduler& m_sched;
  S7CpuPlan m_plan;
  std::optional<devices::Program> m_program;
  std::optional<devices::ProcessImage> m_image;
  std::vector<devices::ProgramEvent> m_program_events;
  std::uint64_t m_scans = 0;
  s7cpu::CpuMemory m_memory;
  s7cpu::CpuInfo m_info;
  std::unique_ptr<mpi_station::S7CpuSessionFactory> m_factory;
  std::unique_ptr<mpi_station::MpiStation> m_mpi;
  // DP I/O map per master (keyed by the master's address and line order of calls).
  std::vector<std::pair<const dp::Master*, std::vector<Slot>>> m_maps;
  std::uint32_t m_next_in = 0, m_next_out = 0, m_unmapped = 0;
  std::uint64_t m_exchanges = 0;
  std::vector<std::uint8_t> m_buf;
  struct DpInterface {
    std::string line;
    dp::Master* master = nullptr;
    bool x1 = false;
  };
  std::vector<DpInterface> m_dp;  ///< X1 first
  std::vector<bool> m_dp_sfc_done;  ///< SFC 11 calls, then SFC 12 calls
  std::vector<DpSfcRecord> m_dp_sfc;
  void run_dp_sfcs(bus::Ticks now);  ///< SFC 11/12 due at this OB 1 (s7_dp_sfc.cpp)
  dp::Master* dp_master_on(const std::string& line) const;
};

/// The MPI interface of one CPU of an h_system: an MPI station whose connections are ad-hoc S7
/// connections of that CPU (HSystemModel::open_s7_adhoc: counted against its connection
/// resources, refused during a link-up/update, R8). `model` gives the running model (nullptr
/// before the H-system runs: connections are then refused). The line powers the station with its
/// CPU (Simulation: the CPU's power-on time, cpu_failure faults), so a CPU that fails leaves the
/// token ring and its connections break at the PGs (PeerLeftRing / PeerGone). Jobs arriving
/// during an update (t1..t5) are held by the model and answered at t5 or the abort through the
/// station's late-answer sink (000 L1673-1680); a session that ended (its CPU lost, R8 at a
/// link-up) gets its MPI connection released at the next job (docs/h-sfc90.md, docs/mpi.md
/// decisions 11 and 12).
class HCpuMpiNode {
 public:
  HCpuMpiNode(const HMpiPlan& plan, int rack, const fdl::BusParams& params,
              std::function<devices::HSystemModel*()> model);
  ~HCpuMpiNode();
  mpi_station::MpiStation& station() { return *m_station; }
  const mpi_station::MpiStation& station() const { return *m_station; }
  const HMpiPlan& plan() const { return m_plan; }
  int rack() const { return m_rack; }
  /// Ends every connection's session now (as a power-off does), so that none outlives the model
  /// (Simulation's destructor: the model goes first).
  void end_sessions(bus::Ticks now) { m_station->on_power_off(now); }

 private:
  class Factory;
  HMpiPlan m_plan;
  int m_rack;
  std::unique_ptr<Factory> m_factory;
  std::unique_ptr<mpi_station::MpiStation> m_station;
};

/// What a PG/OP's read of one item did in the run.
struct S7ReadStats {
  std::uint64_t requests = 0;     ///< Read Var jobs sent
  std::uint64_t ok = 0;           ///< answers with return code FF
  std::uint64_t errors = 0;       ///< answers with another return code (last in `last_code`)
  std::uint8_t last_code = 0;
  std::vector<std::uint8_t> last_value;
  bus::Ticks last_latency = 0;    ///< submit to answer, virtual time
  bus::Ticks max_latency = 0;
};

/// A PG or OP on an MPI line that reads its items from CPUs: one connection per CPU, Setup
/// Communication (PDU 240) once connected, then each item's Read Var every period.
///
/// Decisions:
/// - One job outstanding per connection (AmQ 1, as the CPUs offer). Each read is due on a fixed
///   grid of its period from the first read (the first once the connection is set up); one that
///   comes due while another job is open waits for it, and an answer later than the next due
///   time moves the grid to the answer, so a slow ring shows as latency and fewer reads, not as
///   a queue.
/// - A connection that breaks or is refused is opened again 1 s later (an HMI's retry); every
///   break is counted per reason.
class MpiClientNode final : public bus::EventTarget {
 public:
  MpiClientNode(bus::Scheduler& sched, const MpiStationPlan& plan, const fdl::BusParams& params);

  mpi_station::MpiStation& station() { return m_station; }
  const mpi_station::MpiStation& station() const { return m_station; }
  const MpiStationPlan& plan() const { return m_plan; }
  /// Per planned read, in plan order.
  const std::vector<S7ReadStats>& reads() const { return m_stats; }
  std::uint64_t connects() const { return m_connects; }
  std::uint64_t breaks() const { return m_breaks; }        ///< connections that broke or closed
  std::uint64_t refusals() const { return m_refusals; }   ///< connect requests the CPU refused
  /// Broken or closed connections by reason (mpi_station::to_string(EndReason)).
  const std::map<std::string, std::uint64_t>& ends() const { return m_ends; }

  /// Starts the work at `now` (the station's power-on).
  void start(bus::Ticks now);
  void on_event(bus::Ticks now, std::uint64_t tag) override;

 private:
  struct Peer {
    std::uint8_t cpu = 0;
    std::optional<mpi_station::Handle> handle;
    bool ready = false;       ///< Setup Communication answered
    int outstanding = -1;     ///< the read (index) whose answer is awaited, -1 none
    std::uint16_t next_ref = 1;
    bus::Ticks sent_at = 0;
  };
  void on_station_event(const mpi_station::StationEvent& e);
  void connect(Peer& p);
  void pump(Peer& p, bus::Ticks now);
  Peer* peer_of(mpi_station::Handle h);

  bus::Scheduler& m_sched;
  MpiStationPlan m_plan;
  mpi_station::MpiStation m_station;
  std::vector<Peer> m_peers;
  std::vector<S7ReadStats> m_stats;
  std::vector<bus::Ticks> m_due;  ///< per read: next time it is due
  std::vector<mpi_station::StationEvent> m_pending;  ///< station events not yet handled
  std::uint64_t m_connects = 0, m_breaks = 0, m_refusals = 0;
  std::map<std::string, std::uint64_t> m_ends;
  std::uint64_t m_generation = 0;
};

}  // namespace pbvbus::tools
