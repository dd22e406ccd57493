#pragma once
// An s7_door of a scenario (scenario/include/pbvbus/scenario/s7_plan.hpp; docs/iso-on-tcp.md):
// the ISO-on-TCP door and the router behind it, which sends each client connection where its
// called TSAP's rack/slot says: to a single CPU's memory (as through the CPU's own CP), to an
// H-system (an ad-hoc connection to the master CPU or one of its configured connections), or
// across MPI to a CPU on the door's MPI line (the door's own MPI station as a PG behind a
// router).
//
// Decisions:
// - The door opens with the paced runner (Simulation::paced_runner), like the gateways' doors; a
//   run with a door is paced.
// - Over MPI each client connection is one MPI connection of the door's station to the CPU,
//   opened at the client's CR; the CR is confirmed at once (the door does not wait for the MPI
//   connect confirm) and jobs wait until the MPI connection is up. If it is refused or breaks,
//   the client gets a COTP DR (the route closed). The CPU answers Setup Communication with at
//   most 240 (the MPI data message's limit), which the client then keeps to.
// - To an H-system: a route with `connection` rides on that configured connection
//   (HSystemModel::open_s7_connection: standard ends with its CPU or CP, fault-tolerant survives
//   the master's loss); without, an ad-hoc connection to the master CPU at the client's CR
//   (open_s7_adhoc, ends with that CPU). The session is checked at every job: once the model has
//   closed it, the job goes unanswered and the client gets a COTP DR with the model's reason.
// - The S7 PDUs the door carries go to the capture as upper-PDU records when a capture runs.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/iso_on_tcp/iso_door.hpp"
#include "pbvbus/iso_on_tcp/s7_router.hpp"
#include "pbvbus/mpi_station/mpi_station.hpp"
#include "pbvbus/scenario/s7_plan.hpp"
#include "pbvbus/simulation/s7_nodes.hpp"

namespace pbvbus::tools {

class S7DoorNode final : public iso_on_tcp::S7Router, public bus::EventTarget {
 public:
  /// `cpus`: the run's single CPUs (index = S7Plan::cpus); `mpi_params`: the door's MPI line's
  /// bus parameters when it has one.
  S7DoorNode(bus::Scheduler& sched, const S7DoorPlan& plan, std::vector<S7CpuNode*> cpus,
             const fdl::BusParams* mpi_params,
             std::function<devices::HSystemModel*(int h_system)> h_model = {});
  ~S7DoorNode() override;

  const S7DoorPlan& plan() const { return m_plan; }
  /// The door's MPI station (nullptr without mpi_line).
  mpi_station::MpiStation* mpi() { return m_mpi.get(); }
  const mpi_station::MpiStation* mpi() const { return m_mpi.get(); }
  /// Opens the listener on the runner's io_context; throws std::runtime_error when it cannot.
  void open(bus::PacedRunner& runner);
  /// The port it listens on (0 before open()).
  std::uint16_t port() const { return m_door ? m_door->port() : 0; }
  const iso_on_tcp::IsoDoorStats* stats() const { return m_door ? &m_door->stats() : nullptr; }
  /// Closes the listener and every client connection now (their S7 sessions end while the
  /// CPUs and H models they talk to still exist); idempotent. The run calls it first when it
  /// ends: an H session must not outlive its model (h_s7_session.hpp).
  void close();
  /// Every S7 PDU through the door (for the capture), set before open().
  void set_capture(iso_on_tcp::PduCapture capture) { m_capture = std::move(capture); }

  iso_on_tcp::RouteResult open(const iso_on_tcp::RouteRequest& request) override;
  void on_event(bus::Ticks now, std::uint64_t tag) override;

 private:
  class CpuChannel;
  class MpiChannel;
  class HChannel;
  void on_station_event(const mpi_station::StationEvent& e);

  bus::Scheduler& m_sched;
  S7DoorPlan m_plan;
  std::vector<S7CpuNode*> m_cpus;
  std::function<devices::HSystemModel*(int)> m_h_model;
  std::unique_ptr<mpi_station::MpiStation> m_mpi;
  std::vector<MpiChannel*> m_mpi_channels;  ///< open channels over MPI (owned by the door)
  std::vector<mpi_station::StationEvent> m_pending;
  iso_on_tcp::PduCapture m_capture;
  std::unique_ptr<iso_on_tcp::IsoOnTcpDoor> m_door;
};

}  // namespace pbvbus::tools
