#pragma once
// An IM 157 link of the S7-400H (docs/dp-link.md): a Y-link (two IM 157 + Y-coupler, a
// single-channel DP line below) or a DP/PA link (two IM 157 + DP/PA coupler, PROFIBUS PA
// below) in switched I/O (000 L1773-L1832; 001 L5558-L5566, L8128; seeds-digest §2).
//
// Upper side: a switched station (devices::SwitchedStationModel, PI 2.212 System Redundancy)
// with one address on both upper lines, interface 0 on line A and 1 on line B, the active
// channel chosen by the redundant master's PrmCmd; its GSD is link_gsd_text(): one module per
// lower station, in configured order, so the link's Data_Exchange inputs and outputs are the
// concatenation of the lower stations' (the link is not transparent: the upper masters address
// the link only, the lower stations keep their own addresses on the lower line).
// Lower side: a DP master class 1 (dp::Master on an fdl::ActiveStation) on its own bus::Line
// polling the lower stations with their own configuration (dp::SlaveParams).
//
// Decisions (docs/dp-link.md has the reasons):
// - Outputs: at every token receipt of the lower master, each lower station's outputs are the
//   upper backplane outputs of its module (RedundantSlave::outputs()): held across an upper
//   switchover (the "no pulses" rule), 0 before the first outputs and after Output_Hold_Time.
//   The lower master stays in OPERATE whatever happens on the upper side: the lower line keeps
//   running during an upper switchover (it is an independent bus system; product note 6847578).
// - Inputs: after every confirmation of the lower master, a lower station whose inputs changed
//   (MasterImage::inputs_generation) has them written into its module on both upper interfaces
//   (RedundantSlave::write_inputs). A failed lower station's inputs read 0.
// - Lower station failure (the lower master's StationFailure, S7 OB 86 W#16#39C4 on a plain
//   master): the link shows its module as missing: DP-V1 Module_Status 11B "no module" and the
//   identifier-related bit of that module (dp::SlaveApplication::set_module_state on both
//   interfaces' engines); the H CPUs see it as OB 83 W#16#3961 for the link's module (slot =
//   lower station's position + 1), its return (DataExchangeEntered) as OB 83 W#16#3861; the
//   link itself stays in data exchange (no OB 86 for the link).
// - The coupler's switchover time (T_SLAVE_UM) is an option (default 100 ms for the Y-link,
//   and for the DP/PA link; the IM 157 data sheet is not in the seeds) put into the GSD
//   (Slave_Max_Switch_Over_Time) and made real: the two IM 157 exchange the switchover over
//   their internal link (RedundantSlave: request, take-over = 2 x link_delay), so link_delay =
//   T_SLAVE_UM / 2, switch_timeout = T_SLAVE_UM + 10 ms, supervision >= heartbeat + T_SLAVE_UM +
//   100 ms. A commanded switchover therefore takes T_SLAVE_UM from the PrmCmd to the new
//   PRIMARY; an autonomous one (the primary's engine leaves Data_Exch) T_SLAVE_UM / 2.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp_link/link_gsd.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/switched_io/switched_station.hpp"

namespace pbvbus::devices {

struct DpLinkOptions {
  DpLinkKind kind = DpLinkKind::YLink;
  std::uint8_t address = 3;            ///< the link's address on both upper lines
  fdl::BusParams upper_bus_params;     ///< the upper lines' parameters
  fdl::BusParams lower_bus_params;     ///< the lower line's (PA: 31.25 kbit/s)
  std::uint8_t lower_master_address = 1;  ///< the coupler's own master on the lower line
  bus::Ticks switchover = 100 * bus::kTicksPerMs;  ///< the coupler's T_SLAVE_UM
  redundancy::RedundantSlaveParams redundancy;
  std::string name;  ///< default "<kind> @<address>"
};

class DpLink;
struct DpLinkBuild {
  std::unique_ptr<DpLink> link;
  std::vector<std::string> errors;
  bool ok() const { return link != nullptr; }
};

/// A lower line's transmission rate is allowed for the kind (Y-link: 187.5 kbit/s .. 1.5 Mbit/s;
/// DP/PA link: 31.25 kbit/s only); empty = ok, else the reason.
std::string check_lower_baud(DpLinkKind kind, bus::Baud baud);

class DpLink {
 public:
  /// `lower` = the lower stations as the coupler's master is configured for them (address,
  /// ident, Set_Prm, Chk_Cfg modules), in the order that becomes the link's modules.
  static DpLinkBuild build(DpLinkOptions options, std::vector<dp::SlaveParams> lower);
  ~DpLink();
  DpLink(const DpLink&) = delete;
  DpLink& operator=(const DpLink&) = delete;

  const std::string& name() const { return m_name; }
  DpLinkKind kind() const { return m_kind; }
  std::uint8_t address() const { return m_upper->address(); }
  /// The link's GSD (link_gsd_text) as parsed, for the upper masters' configuration.
  const GsdFile& gsd() const { return *m_gsd; }
  /// What a configuration tool puts into each upper master for the link (with an 8-octet
  /// PrmCmd block to be filled by the redundant master system).
  dp::SlaveParams upper_slave_params() const;
  bus::Ticks switchover_time() const { return m_switchover; }

  SwitchedStationModel& upper() { return *m_upper; }
  const SwitchedStationModel& upper() const { return *m_upper; }
  dp::Master& lower_master();
  const dp::Master& lower_master() const;
  fdl::ActiveStation& lower_station();

  /// Attaches upper interface i (0 = line A, 1 = line B).
  bus::AttachmentId attach_upper(int i, bus::Line& line, std::string label = {});
  /// Attaches the coupler's master to the lower line.
  bus::AttachmentId attach_lower(bus::Line& line, std::string label = {});

  /// The lower stations in module order; module index of a lower address (nullopt = none).
  const std::vector<std::uint8_t>& lower_addresses() const { return m_lower; }
  std::optional<std::size_t> module_of(std::uint8_t lower_address) const;
  /// Whether the link currently shows the lower station's module as missing.
  bool lower_failed(std::uint8_t lower_address) const;
  /// The lower master's events (after the link used them).
  void set_lower_event_handler(dp::MasterEventHandler h) { m_lower_events = std::move(h); }

 private:
  class Node;
  DpLink() = default;
  void copy_outputs();
  void copy_inputs();
  void on_lower_event(const dp::MasterEvent& e);
  void set_module_missing(std::size_t module, bool missing);

  std::string m_name;
  DpLinkKind m_kind = DpLinkKind::YLink;
  bus::Ticks m_switchover = 0;
  std::unique_ptr<GsdFile> m_gsd;
  std::vector<ModuleChoice> m_choices;
  std::unique_ptr<SwitchedStationModel> m_upper;
  std::unique_ptr<Node> m_node;
  std::vector<std::uint8_t> m_lower;           ///< lower addresses, module order
  std::vector<std::uint32_t> m_in_gen;         ///< last copied inputs generation per module
  std::vector<bool> m_missing;                 ///< module shown as missing
  std::vector<std::uint8_t> m_buf;
  dp::MasterEventHandler m_lower_events;
};

}  // namespace pbvbus::devices
