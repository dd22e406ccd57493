#pragma once
// A simulated DP slave built from a GSD file and a module list (protocol-facts.md §I for the
// GSD, §D for DP, §E.5 for alarms, §C.1 for MaxTsdr): the device a scenario attaches to a line.
//
// SlaveModel derives the dp::SlaveConfig from the GSD (ident, features, User_Prm_Data length and
// content check, real configuration = the chosen modules' identifier octets, Min_Slave_Intervall,
// Max_Diag_Data_Len), owns the fdl::PassiveStation + dp::SlaveEngine pair, feeds the inputs from
// per-module I/O behaviours (io_behaviour.hpp) and applies faults (slave_fault.hpp) at given
// virtual times. It is itself the bus::Device to attach: it wraps the passive station.
//
// How it gets time (sans-I/O, never a wall clock):
// - Inputs are computed lazily, just before the slave engine sees each request (the model sits
//   between the passive station and the engine as its fdl::ResponderUser), from the request's
//   virtual time. So a Data_Exchange answer carries exactly the behaviour's value at the end of
//   the request frame, with no periodic events at all. "Every DP cycle" counters count the
//   owner's Data_Exchange requests (FCB repeats never reach the user, so they do not count).
//   Between requests the process image holds the value of the last request.
// - Faults scheduled with schedule() fire from the device's own timer: the model multiplexes the
//   single DevicePort timer between the passive station and its fault list, so a fault applies at
//   its exact tick even on a silent line. schedule() may be called before the line starts or from
//   any event on the bus thread (it re-arms the timer).
//
// Decisions, as a PROFIBUS engineer would expect them:
// - User_Prm_Data: the slave accepts exactly the length the GSD assembly gives for its module list
//   (after truncation to Max_User_Prm_Data_Len), and every Ext_User_Prm_Data_Ref parameter in it
//   (station area, then each module's area in module order) must hold a value its ExtUserPrmData
//   allows; anything else → Prm_Fault. Constant octets are not checked (vendors differ; most
//   ignore reserved bits). A DP-V1 slave with Prm_Block_Structure_supp also accepts structured
//   parameter blocks after that part (up to 237 octets in all); the check covers the GSD part.
// - TSDR: the station's own delay in bit times; unset = the line's min TSDR (a fast ASIC). It must
//   lie within [bus min TSDR, the GSD's MaxTsdr for the line's baud]; a baud the GSD does not
//   support is a build error (a real slave would never sync to it).
// - Max_Alarm mode: the highest Alarm_Mode whose alarm count (1, 2, 4, 8, 12, 16, 24, 32) fits
//   Alarm_Sequence_Mode_Count; 0 when the GSD gives none.
// - Mute ("stops answering"): the receiver is deaf and the transmitter silent — incoming frames
//   are dropped before the passive station (so FDL Status goes unanswered too) and a reply already
//   scheduled is suppressed. The engine keeps running, so its watchdog expires as in a real slave
//   whose bus interface hangs; after unmute the master re-parameterises it. Powering the station
//   off is the line's job (bus::Line::set_power on the attachment).
// - Pulled module: its module state is NoModule (identifier-related bit, and the DP-V1
//   Module_Status block), its inputs read zero and its behaviour is suspended until plugged; a
//   DP-V1 slave whose GSD has Pull_Plug_Alarm_supp raises a Pull alarm (slot = module + 1,
//   specifier "appears") and on plugging a Plug alarm ("disappears"); the engine drops them if the
//   master did not enable them.
// - Channel diagnosis refers to a module; the channel block carries the module's first identifier
//   number (Chk_Cfg order), as the standard numbers identifiers. With `alarm` set, a DP-V1 slave
//   also raises a Diagnostic alarm for the module's slot (data = the 3 channel octets).
// - SlaveStop / SlaveRun (F15, an intelligent slave whose own CPU stops; digest §6 "DP master
//   event detection"): the DP interface keeps running, so the slave STAYS in data exchange (a
//   CPU in STOP does not leave the bus; the master's failure detection is not involved); its
//   inputs read 0 (its program no longer writes them) and outputs are ignored by it; its
//   diagnosis gets Ext_Diag and the S7 diagnostic record 0 {01 00 04 00} (MDL_DEFECT, MDL_STOP =
//   octet 2 bit 2; slave_fault.hpp) — for a DP-V0 slave as a free-format device-related block
//   `05 01 00 04 00`, for a DP-V1 slave as a Status_Message PDU (0x81, slot 0, specifier
//   "appears") `08 81 00 01 01 00 04 00`, because a DP-V1 master reads the second octet of a
//   device-related block as an alarm/status type. Back to RUN: the block is removed (its
//   absence is MDL_STOP = 0) and Ext_Diag cleared; inputs follow the behaviours again. Each
//   change makes the next Data_Exchange answer DH, so the master reads the new diagnosis.
// - Mutants (SlaveModelOptions::mutant): tsdr_too_late, ignore_min_tsdr and ignore_fcb become an
//   fdl::PassiveMutation on the station, the others a dp::EngineMutation in the SlaveConfig
//   (derive_slave_setup). A mutant changes nothing else; SlaveModel::mutant() reports it.
// - Time-based behaviours use absolute virtual time (tick 0 = line start), so values at a given
//   time are known in advance and survive power cycles.

#include <cstdint>
#include <functional>
#include <span>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/io_behaviour.hpp"
#include "pbvbus/slaves/module_records.hpp"
#include "pbvbus/slaves/slave_fault.hpp"
#include "pbvbus/slaves/slave_mutant.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/fdl/passive_station.hpp"

namespace pbvbus::devices {

/// A module as a scenario names it: by its GSD name, or by index into the GSD's module list.
struct ModuleChoice {
  std::string name;                  ///< used when index is empty
  std::optional<std::size_t> index;  ///< 0-based into GsdFile::modules()
  static ModuleChoice named(std::string n) { return {std::move(n), std::nullopt}; }
  static ModuleChoice at(std::size_t i) { return {{}, i}; }
  /// "#n" = index n, anything else = a name.
  static ModuleChoice parse(std::string_view text);
};

struct SlaveModelOptions {
  std::uint8_t address = 3;  ///< 0..126
  fdl::BusParams bus_params;  ///< the line's parameters (baud, min TSDR)
  std::optional<std::uint32_t> tsdr;  ///< own station delay in t_bit; unset = bus min TSDR
  std::string name;           ///< for reports; default "<Model_Name> @<address>"
  /// Test-only: a mutant that breaks one rule on purpose (slave_mutant.hpp, docs/mutants.md).
  /// tsdr_too_late replaces `tsdr` by the GSD's MaxTsdr at the line's baud + 20 t_bit and skips
  /// the MaxTsdr bound check; the others leave the setup as it is.
  std::optional<SlaveMutant> mutant;
};

class SlaveModel;

/// An I/O behaviour for input octets [offset, offset + width) of one module (a channel).
struct ChannelBehaviour {
  std::size_t offset = 0;
  std::size_t width = 0;
  IoBehaviour behaviour;
};
/// Why a channel behaviour does not fit module `module` of `layout`; empty = it fits.
std::string check_channel_behaviour(const dp::SlaveLayout& layout, std::size_t module,
                                    std::size_t offset, std::size_t width, const IoBehaviour& b);
/// The output octets of a module, for Echo behaviours.
using EchoSource = std::function<std::span<const std::uint8_t>(std::size_t module)>;
/// Writes the channels' values into `buf` (module `module`'s input octets, read beforehand from
/// the image) at virtual time `now` after `cycles` DP cycles; later channels win on overlap.
void apply_channel_behaviours(std::span<std::uint8_t> buf, std::size_t module,
                              const std::vector<ChannelBehaviour>& channels, bus::Ticks now,
                              std::uint64_t cycles, const EchoSource& outputs);
/// What SlaveModel::build() returns: a model, or every reason it cannot be built.
struct SlaveModelBuild {
  std::unique_ptr<SlaveModel> model;
  std::vector<std::string> errors;
  std::vector<std::string> notes;  ///< e.g. User_Prm_Data truncated
  bool ok() const { return model != nullptr; }
};

/// Module indices into GsdFile::modules() for a list of choices; errors name the bad entries.
GsdOutcome<std::vector<std::size_t>> resolve_modules(const GsdFile& gsd,
                                                     const std::vector<ModuleChoice>& modules);

/// What a configuration tool puts into a class-1 master for this slave (ident, Set_Prm with the
/// GSD-assembled User_Prm_Data, Chk_Cfg = the modules' identifiers, Min_Slave_Interval,
/// Fail_Safe, C1_Response_Timeout). Errors as resolve_modules() and GsdFile::user_prm_data().
GsdOutcome<dp::SlaveParams> master_slave_params(const GsdFile& gsd,
                                                const std::vector<ModuleChoice>& modules,
                                                std::uint8_t address,
                                                const std::vector<GsdPrmSetting>& settings = {});

/// Everything a GSD and a module list say about a slave, checked against the options (address,
/// baud, TSDR): the chosen module indices, the User_Prm_Data the slave expects (defaults), its
/// station delay and its dp::SlaveConfig (features, prm length and content check, real
/// configuration, Min_Slave_Intervall, Max_Diag_Data_Len, PrmCmd_supp). Shared by SlaveModel and
/// SwitchedStationModel; errors name every reason it cannot be built.
struct SlaveSetup {
  std::vector<std::size_t> modules;
  GsdBytes user_prm;
  std::uint32_t tsdr = 0;
  dp::SlaveConfig config;
  std::vector<std::string> errors;
  std::vector<std::string> notes;
  bool ok() const { return errors.empty(); }
};
SlaveSetup derive_slave_setup(const GsdFile& gsd, const std::vector<ModuleChoice>& modules,
                              const SlaveModelOptions& options);

class SlaveModel final : public bus::Device {
 public:
  static SlaveModelBuild build(const GsdFile& gsd, const std::vector<ModuleChoice>& modules,
                               SlaveModelOptions options);
  ~SlaveModel() override;
  SlaveModel(const SlaveModel&) = delete;
  SlaveModel& operator=(const SlaveModel&) = delete;

  const std::string& name() const { return m_name; }
  std::uint8_t address() const { return m_station->address(); }
  std::uint32_t tsdr() const { return m_tsdr; }
  const dp::SlaveConfig& config() const { return m_engine->config(); }
  dp::SlaveEngine& engine() { return *m_engine; }
  dp::SlaveApplication& application() { return m_engine->application(); }
  fdl::PassiveStation& station() { return *m_station; }
  std::size_t module_count() const { return m_modules.size(); }
  /// Index into the GSD's module list of module m.
  std::size_t gsd_module(std::size_t m) const { return m_modules[m].gsd_index; }
  /// The User_Prm_Data the slave expects (all parameters at their defaults).
  const GsdBytes& default_user_prm() const { return m_default_prm; }
  /// The mutant this model was built with (test-only), if any.
  std::optional<SlaveMutant> mutant() const { return m_mutant; }

  // --- I/O behaviours (before start or on the bus thread). Errors: empty string = ok.
  /// Replaces module m's behaviours by one covering all its input octets.
  std::string set_behaviour(std::size_t module, IoBehaviour b);
  /// Adds a behaviour for input octets [offset, offset + width) of module m (a channel); later
  /// channels win where they overlap earlier ones.
  std::string add_channel_behaviour(std::size_t module, std::size_t offset, std::size_t width,
                                    IoBehaviour b);
  /// Number of Data_Exchange requests from the owner seen so far (the DP cycle count).
  std::uint64_t dp_cycles() const { return m_dp_cycles; }

  // --- Faults (bus thread). apply() acts at once; schedule() at a virtual time.
  std::string apply(const SlaveFault& f);
  std::string schedule(bus::Ticks at, SlaveFault f);
  bool muted() const { return m_muted; }
  bool module_pulled(std::size_t m) const { return m_modules[m].pulled; }
  /// The modules' parameter data records (MSAC_C1 Write/Read; module_records.hpp); null unless
  /// the GSD has DPV1_Slave and C1_Read_Write_supp.
  const ModuleRecords* module_records() const { return m_records.get(); }
  /// F15: the slave's own CPU is in STOP.
  bool stopped() const { return m_stopped; }

  // --- bus::Device
  void on_power_on(bus::Ticks now) override;
  void on_power_off(bus::Ticks now) override;
  void on_frame(const bus::RxFrame& frame) override;
  void on_timer(bus::Ticks now) override;
  int receive_filter() const override { return m_station->receive_filter(); }
  const char* kind() const override { return "DP slave"; }

 private:
  class User;
  class Port;
  struct Module {
    std::size_t gsd_index = 0;
    std::vector<ChannelBehaviour> channels;
    bool pulled = false;
  };
  struct Scheduled {
    bus::Ticks at = 0;
    std::uint64_t order = 0;
    SlaveFault fault;
  };

  SlaveModel() = default;
  std::string check_fault(const SlaveFault& f) const;
  void do_apply(const SlaveFault& f);
  void refresh_inputs(bus::Ticks now);
  void run_due(bus::Ticks now);
  void rearm();

  std::string m_name;
  std::uint32_t m_tsdr = 0;
  GsdBytes m_default_prm;
  bool m_dpv1_pull_plug = false;
  bool m_dpv1 = false;
  std::optional<SlaveMutant> m_mutant;
  std::unique_ptr<ModuleRecords> m_records;  ///< before m_engine: outlives its handlers
  std::unique_ptr<dp::SlaveEngine> m_engine;
  std::unique_ptr<User> m_user;
  std::unique_ptr<Port> m_port;
  std::unique_ptr<fdl::PassiveStation> m_station;
  std::vector<Module> m_modules;
  std::vector<std::uint8_t> m_scratch;
  std::vector<std::uint8_t> m_out_scratch;
  std::vector<Scheduled> m_faults;  ///< pending, sorted by (at, order)
  std::uint64_t m_fault_order = 0;
  std::uint64_t m_dp_cycles = 0;
  bool m_muted = false;
  bool m_stopped = false;
  bool m_powered = false;
  bus::Ticks m_station_timer = bus::kNever;
  bus::Ticks m_armed = bus::kNever;
};

}  // namespace pbvbus::devices
