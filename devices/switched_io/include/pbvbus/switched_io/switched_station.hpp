#pragma once
// A switched station on two real lines (docs/redundancy.md; protocol-facts.md §G, docs/redundancy.md):
// one PROFIBUS address, two DP slave interfaces (interface 0 for line A, interface 1 for line B),
// one backplane, built from a GSD that declares System Redundancy (PrmCmd_supp = 1,
// Slave_Redundancy_supp bit 0) and a module list, like SlaveModel.
//
// assumption: modelled as PI 2.212 System Redundancy; the Siemens IM 153-2 wire protocol is not
// public.
//
// SwitchedStationModel owns a redundancy::RedundantSlave (roles, internal link, PrmCmd,
// Red_Status, Output_Hold_Time) and two bus::Devices, interface_device(0) and (1), each an
// fdl::PassiveStation with the station's address in front of that interface's slave engine.
// Decisions:
// - Configuration: derive_slave_setup() as for SlaveModel (ident, features, User_Prm_Data check,
//   real configuration, TSDR against the GSD's MaxTsdr); both lines must run at the same baud
//   (one set of bus parameters in the options).
// - Timers: the RedundantSlave's next_deadline() is armed on BOTH interface devices' ports, and
//   re-armed on both after every call the line makes into either (frame, timer, power), so a
//   change made through one interface (a PrmCmd on line A that starts the link exchange, a
//   watchdog) wakes the station even if the other line is silent, and a line that is powered off
//   or whose device is detached does not stop the station. Whichever fires first runs
//   RedundantSlave::on_time(); the other wake-up finds nothing due.
// - Inputs: computed once per request time from the I/O behaviours (SlaveModel's
//   apply_channel_behaviours) and written into both interfaces' images
//   (RedundantSlave::write_inputs), just before the interface that got the request answers. Echo
//   reads the BACKPLANE outputs (what the modules see), not an interface's image. dp_cycles()
//   counts the Data_Exchange requests the PRIMARY interface accepts (one cycle of the station,
//   not one per line).
// - Faults: fail_interface(i) fails the interface in the RedundantSlave and, when the device was
//   attached with attach(), the transceiver of its attachment (Line::set_transceiver_ok), so FDL
//   Status goes silent too; repair_interface(i) undoes both. A device attached by hand with
//   Line::attach() leaves the transceiver to the caller.
// - Power: the backplane (RedundantSlave) powers on with the first interface device the line
//   powers; powering one attachment off silences that interface's FDL station only (the
//   backplane has its own supply). Station power loss is power_off_station(): the
//   RedundantSlave's power_off (both interfaces silent, backplane outputs 0, link messages lost),
//   both FDL stations off (FDL Status silent too, FCBs forgotten) and, for devices attached with
//   attach(), both transceivers off as fail_interface() does. power_on_station() undoes it: a
//   cold start of the station (S_PRIMARY/S_WAITING alternation, engines in Wait_Prm); the
//   masters re-parameterise it and the next Primary_Request chooses the PRIMARY. A failed
//   interface stays failed (and its transceiver off) across the power cycle.
// - Alarms: raise_alarm() goes to RedundantSlave::raise_alarm (on the PRIMARY only, kept until
//   acknowledged through the PRIMARY, raised again on a new PRIMARY; see redundant_slave.hpp).
// - T_SLAVE_UM: the GSD's Slave_Max_Switch_Over_Time (unit 10 ms, assumption in gsd.hpp).
// - Flying Redundancy (options.redundancy.mode = Flying; §G.1): both interface devices go on ONE
//   line; interface 0 starts at `address` (A), interface 1 at A + 64. Refused unless the GSD's
//   Slave_Redundancy_supp has the Flying bit (0x02) and A <= 61. The FDL stations' addresses
//   follow RedundantSlave::address_offset(): after every call the line makes into either
//   interface device (frame, timer, power) and after fail/repair_interface() the model sets
//   both stations' addresses (fdl::PassiveStation::set_address, which re-reads the line's
//   receive filter and forgets the FCBs). The swap happens inside RedundantSlave::on_time() or
//   a request, so the stations change address in the same call, at the same virtual time. A
//   reply already scheduled by the request that caused the swap still goes out with the old
//   address (as after Set_Slave_Add). build() refuses System Redundancy unless bit 0 is set.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/io_behaviour.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/fdl/passive_station.hpp"
#include "pbvbus/redundancy/redundant_slave.hpp"

namespace pbvbus::devices {

struct SwitchedStationOptions {
  std::uint8_t address = 3;   ///< 0..126, the same on both lines (Flying: A, 0..61)
  fdl::BusParams bus_params;  ///< both lines' parameters (baud, min TSDR)
  std::optional<std::uint32_t> tsdr;  ///< own station delay in t_bit; unset = bus min TSDR
  std::string name;           ///< default "<Model_Name> @<address>"
  redundancy::RedundantSlaveParams redundancy;  ///< link delay, supervision, Tsprimary, ...
};

class SwitchedStationModel;
struct SwitchedStationBuild {
  std::unique_ptr<SwitchedStationModel> model;
  std::vector<std::string> errors;
  std::vector<std::string> notes;
  bool ok() const { return model != nullptr; }
};

class SwitchedStationModel {
 public:
  static SwitchedStationBuild build(const GsdFile& gsd, const std::vector<ModuleChoice>& modules,
                                    SwitchedStationOptions options);
  ~SwitchedStationModel();
  SwitchedStationModel(const SwitchedStationModel&) = delete;
  SwitchedStationModel& operator=(const SwitchedStationModel&) = delete;

  const std::string& name() const { return m_name; }
  /// The station address (Flying Redundancy: the primary address A).
  std::uint8_t address() const { return m_address; }
  /// The address interface i's FDL station answers at now (Flying: A or A + 64).
  std::uint8_t interface_address(int i) const;
  redundancy::RedundancyMode mode() const { return m_rs->params().mode; }
  std::uint32_t tsdr() const { return m_tsdr; }
  const dp::SlaveConfig& config() const { return m_rs->engine(0).config(); }
  const GsdBytes& default_user_prm() const { return m_default_prm; }
  /// The station's own switchover time T_SLAVE_UM (GSD Slave_Max_Switch_Over_Time); nullopt
  /// when the GSD does not state it.
  std::optional<bus::Ticks> t_slave_um() const { return m_t_slave_um; }

  /// The bus::Device of interface i (0 = line A, 1 = line B).
  bus::Device& interface_device(int i);
  /// Attaches interface i to `line` and remembers the attachment for fail/repair_interface().
  bus::AttachmentId attach(int i, bus::Line& line, std::string label = {});

  redundancy::RedundantSlave& redundant_slave() { return *m_rs; }
  redundancy::Role role(int i) const { return m_rs->role(i); }
  int primary() const { return m_rs->primary(); }
  /// The backplane outputs (what the modules drive), all modules in configuration order.
  std::span<const std::uint8_t> outputs() const { return m_rs->outputs(); }
  bool outputs_held() const { return m_rs->outputs_held(); }
  bus::Ticks output_hold_time() const { return m_rs->output_hold_time(); }
  const std::vector<redundancy::RedEvent>& events() const { return m_events; }
  std::uint64_t dp_cycles() const { return m_dp_cycles; }

  // --- I/O behaviours on the backplane (as SlaveModel; empty string = ok)
  std::string set_behaviour(std::size_t module, IoBehaviour b);
  std::string add_channel_behaviour(std::size_t module, std::size_t offset, std::size_t width,
                                    IoBehaviour b);

  // --- Faults (bus thread, at the current virtual time of the lines)
  void fail_interface(int i);
  void repair_interface(int i);
  /// Station power loss and return (both interfaces, the backplane, the internal link).
  void power_off_station();
  void power_on_station();
  bool station_powered() const { return m_rs->powered(); }

  // --- DP-V1 alarms over the active channel (bus thread; as dp::SlaveApplication::raise_alarm)
  dp::AlarmResult raise_alarm(std::uint8_t type, std::uint8_t slot, dp::AlarmSpec spec,
                              bool add_ack, std::span<const std::uint8_t> data = {},
                              std::uint8_t* seq_nr = nullptr);
  std::size_t alarms_outstanding() const { return m_rs->alarms_outstanding(); }

  /// Pulls (true) or plugs module `module` on the backplane (F3; as SlaveModel's ModulePulled):
  /// Module_Status "no module" on both interfaces, its inputs 0 and its behaviours suspended
  /// while pulled, its parameter records forgotten, and a Pull (Plug) alarm over the active
  /// channel when the master enabled them. Empty string = done; else why not.
  std::string set_module_pulled(std::size_t module, bool pulled);
  bool module_pulled(std::size_t module) const {
    return module < m_pulled.size() && m_pulled[module];
  }
  /// The modules' parameter data records (MSAC_C1 Write/Read on either interface; one
  /// backplane, one store: slaves/module_records.hpp); null without C1_Read_Write_supp.
  const ModuleRecords* module_records() const { return m_records.get(); }

 private:
  class Iface;
  class User;
  class Port;

  SwitchedStationModel() = default;
  void refresh_inputs(bus::Ticks now);
  void rearm_all();
  /// Flying Redundancy: each FDL station's address from RedundantSlave::address_offset().
  void sync_addresses();
  /// After every call from a line or a fault: addresses, then the timers of both lines.
  void after_call() {
    sync_addresses();
    rearm_all();
  }
  bus::Ticks now() const;

  std::string m_name;
  std::uint8_t m_address = 0;
  std::uint32_t m_tsdr = 0;
  GsdBytes m_default_prm;
  std::optional<bus::Ticks> m_t_slave_um;
  std::unique_ptr<ModuleRecords> m_records;  ///< before m_rs: outlives the handlers it installs
  std::unique_ptr<redundancy::RedundantSlave> m_rs;
  std::unique_ptr<Iface> m_if[2];
  std::vector<std::vector<ChannelBehaviour>> m_channels;  ///< per module
  std::vector<bool> m_pulled;  ///< per module (set_module_pulled)
  std::vector<std::uint8_t> m_scratch;
  std::vector<redundancy::RedEvent> m_events;
  std::uint64_t m_dp_cycles = 0;
};

}  // namespace pbvbus::devices
