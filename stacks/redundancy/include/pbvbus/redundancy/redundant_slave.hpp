#pragma once
// The slave side of a switched station (PI 2.212 System Redundancy; protocol-facts.md §G,
// seeds-digest.md §2): two DP slave interfaces with the SAME address, each on its own line (each
// a dp::SlaveEngine to put behind its own fdl::PassiveStation), over one backplane (one process
// image, one set of modules, outputs driven from one place), coordinated over an internal link.
//
// assumption: modelled as PI 2.212 System Redundancy; the Siemens IM 153-2 wire protocol is not
// public. Sans-I/O: no threads, no clock. Whoever owns it calls on_time(now) at next_deadline()
// (each interface's ResponderUser reports the same deadline, so the station on either line can
// drive it, but a change made through one interface does not re-arm the other line's timer:
// devices::SwitchedStationModel re-arms both lines' ports after every call); tests call it by
// hand.
//
// Decisions (docs/redundancy.md has the state machine):
// - Internal link: messages (heartbeat with the sender's role, switchover request, take-over,
//   become-backup) arrive after `link_delay` (default 1 ms). Each working interface sends a
//   heartbeat every `heartbeat_period` (100 ms, from power-on); an interface that hears nothing
//   from its partner for `supervision` (300 ms, SIPROTEC RedCom) after the last message counts
//   it as lost (event PartnerLost). A failed interface sends and answers nothing; messages to it
//   are lost.
// - Start-up: interface 0 begins in S_PRIMARY, interface 1 in S_WAITING; they swap after
//   Tsprimary, which starts at 2 s and doubles after every swap up to 32 s (AUMA), until a
//   master's PrmCmd Primary_Request makes one PRIMARY (its partner becomes BACKUP when the
//   link message arrives). Until then no interface drives the backplane: outputs stay safe (0).
//   In S_PRIMARY the Red_State shows Primary, in S_WAITING neither Primary nor Backup.
// - Commanded switchover: Primary_Request to the BACKUP → BP_SWITCHOVER, switchover request to
//   the primary; on arrival the primary becomes BACKUP (outputs held) and sends take-over; on
//   its arrival the requester becomes PRIMARY and sets Prm_Cmd_Ack. 2 × link_delay. Primary_
//   Request to the primary: acknowledged, no change. With the partner lost: PRIMARY at once.
// - Autonomous switchover (System Redundancy lets the slave switch on error, §G.1): when the
//   PRIMARY interface's engine leaves Data_Exch (watchdog expiry, new Set_Prm, ...) while the
//   partner's is in Data_Exch, it becomes BACKUP and sends take-over (1 × link_delay); when the
//   BACKUP notices its partner lost it becomes PRIMARY at once. No switch back after a repair:
//   a repaired interface starts in S_WAITING and the primary tells it to become BACKUP.
// - Backplane outputs: only the PRIMARY interface's accepted Data_Exchange outputs (after its
//   engine applied them: Clear_Data and fail-safe zeros included) reach the backplane. When the
//   primary role is lost the outputs keep their last value until the new PRIMARY accepts its
//   first Data_Exchange, and at most Output_Hold_Time (from the last PrmCmd, else
//   `output_hold` = 1 s); then they go to the safe state (0) and stay there until fresh outputs
//   arrive (event OutputHoldExpired). The backup's outputs never reach the backplane.
// - Inputs and diagnosis: write_inputs() writes both interfaces' images; device diagnosis is
//   set on both through each engine's application().
// - Status blocks: Red_Status (0x9F) is kept current in both interfaces' diagnosis (Red_State_1
//   own, Red_State_2 the partner's as the station knows it now, without a link delay); every
//   change makes the next Data_Exchange DH. Prm_Cmd_Ack (0x9E) echoes the last PrmCmd's Seq_Nr
//   and Function once the command is carried out.
// - Flying Redundancy (params.mode = Flying; §G.1): both interfaces on ONE line, the primary
//   address A and the backup address A + 64 (A <= 61, checked by whoever sets the addresses:
//   devices::SwitchedStationModel). address_offset(i) says which one interface i answers at:
//   interface 0 starts at A, interface 1 at A + 64. The addresses follow the PRIMARY role: when an
//   interface that sits at A + 64 becomes PRIMARY (commanded: at the take-over, 2 × link_delay
//   after the Primary_Request; autonomous: at the take-over or when the backup notices the
//   primary lost) the two interfaces swap addresses at that instant (event AddressSwap, iface =
//   the new primary). Between the old primary's hand-over and the take-over both are BACKUP at
//   their old addresses. Roles, link, PrmCmd and outputs as in System Redundancy.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/redundancy/prm_cmd.hpp"
#include "pbvbus/redundancy/red_status.hpp"

namespace pbvbus::redundancy {

/// VPC3-like redundancy states (§G.4), reduced to what the model distinguishes.
enum class Role : std::uint8_t {
  SWaiting,      ///< start-up, not ready to become primary
  SPrimary,      ///< start-up, ready to become primary
  Primary,
  Backup,
  BpSwitchover,  ///< backup asked the primary to hand over (Primary_Request), waiting
  Failed,        ///< injected interface failure: silent on the bus and on the link
};
std::string_view to_string(Role r);

enum class RedundancyMode : std::uint8_t {
  System,  ///< two lines, the same address on both interfaces
  Flying,  ///< one line, primary at A, backup at A + 64, swapped on switchover
};
std::string_view to_string(RedundancyMode m);
inline constexpr std::uint8_t kFlyingAddressOffset = 64;
/// Highest primary address A with Flying Redundancy (A + 64 must be a slave address <= 125).
inline constexpr std::uint8_t kFlyingMaxAddress = 61;

struct RedundantSlaveParams {
  RedundancyMode mode = RedundancyMode::System;
  bus::Ticks link_delay = bus::kTicksPerMs;
  bus::Ticks heartbeat_period = 100 * bus::kTicksPerMs;
  bus::Ticks supervision = 300 * bus::kTicksPerMs;
  bus::Ticks tsprimary_start = 2000 * bus::kTicksPerMs;
  bus::Ticks tsprimary_max = 32000 * bus::kTicksPerMs;
  bus::Ticks output_hold = 1000 * bus::kTicksPerMs;  ///< until a PrmCmd sets Output_Hold_Time
  bool autonomous_switchover = true;
};

struct RedEvent {
  enum class Kind : std::uint8_t { RoleChanged, PartnerLost, PartnerBack, OutputHoldExpired, AddressSwap };
  Kind kind = Kind::RoleChanged;
  bus::Ticks at = 0;
  int iface = 0;  ///< the interface concerned (for PartnerLost/Back: the one that noticed)
  Role from = Role::SWaiting;
  Role to = Role::SWaiting;
};

class RedundantSlave {
 public:
  /// `cfg` describes the station (both interfaces); PrmCmd and structured prm support are
  /// switched on. Throws std::invalid_argument like dp::SlaveEngine.
  explicit RedundantSlave(dp::SlaveConfig cfg, RedundantSlaveParams p = {});
  RedundantSlave(const RedundantSlave&) = delete;
  RedundantSlave& operator=(const RedundantSlave&) = delete;
  ~RedundantSlave();

  /// The ResponderUser of interface 0 or 1, to put behind an fdl::PassiveStation.
  fdl::ResponderUser& interface(int i);
  dp::SlaveEngine& engine(int i) { return *m_if[i].engine; }

  Role role(int i) const { return m_if[i].role; }
  RedState red_state(int i) const;
  /// The PRIMARY interface, or -1.
  int primary() const;
  const RedundantSlaveParams& params() const { return m_p; }
  /// Flying Redundancy: 0 if interface i answers at the primary address A, 64 if at A + 64.
  /// Always 0 with System Redundancy.
  std::uint8_t address_offset(int i) const {
    if (m_p.mode != RedundancyMode::Flying) return 0;
    return (i == 1) != m_swapped ? kFlyingAddressOffset : 0;
  }

  // Backplane (bus thread).
  bool write_inputs(std::size_t module, std::span<const std::uint8_t> data);
  std::span<const std::uint8_t> outputs() const { return m_out; }
  /// True while outputs are held across a switchover (no fresh outputs yet).
  bool outputs_held() const { return m_hold_deadline != bus::kNever; }
  bus::Ticks output_hold_time() const { return m_hold_time; }

  void on_event(std::function<void(const RedEvent&)> cb) { m_cb = std::move(cb); }

  // Fault injection.
  void fail_interface(int i, bus::Ticks now);
  void repair_interface(int i, bus::Ticks now);

  void power_on(bus::Ticks now);
  bus::Ticks next_deadline() const;
  void on_time(bus::Ticks now);

 private:
  class Port;
  enum class Msg : std::uint8_t { Heartbeat, SwitchReq, TakeOver, BecomeBackup };
  struct LinkMsg {
    bus::Ticks at;
    int to;
    Msg msg;
    Role sender_role;
  };
  struct Iface {
    std::unique_ptr<dp::SlaveEngine> engine;
    std::unique_ptr<Port> port;
    Role role = Role::SWaiting;
    bool partner_lost = false;
    bus::Ticks last_heard = 0;
    bus::Ticks next_heartbeat = bus::kNever;
    bool baudrate_found = false;
    bool master_state_clear = false;
    bool was_data_exch = false;
    bool ack_pending = false;
    std::uint8_t cmd_spec = 0;      ///< specifier octet of the last PrmCmd
    std::uint8_t cmd_function = 0;  ///< Function of the last PrmCmd
    std::int32_t status_cache = -1;
  };

  dp::PrmCmdResult handle_prm_cmd(int i, const dp::PrmCmdView& v);
  void before_request(int i, bus::Ticks now);
  void after_request(int i, bus::Ticks now, std::uint64_t dx_before, std::uint64_t rs_before);
  void send(int from, Msg m, bus::Ticks now);
  void deliver(const LinkMsg& m, bus::Ticks now);
  void set_role(int i, Role r, bus::Ticks now);
  void check_primary_lost_master(bus::Ticks now);
  void lose_primary(bus::Ticks now);  ///< backplane: start the hold
  void take_outputs(int i);
  void refresh_status();
  void set_ack(int i);
  void emit(RedEvent::Kind k, bus::Ticks at, int iface, Role from = Role::SWaiting,
            Role to = Role::SWaiting);
  bool alive(int i) const { return m_if[i].role != Role::Failed; }
  bool partner_in_dx(int i) const;

  RedundantSlaveParams m_p;
  std::array<Iface, 2> m_if;
  std::vector<LinkMsg> m_link;  ///< in arrival order
  std::vector<std::uint8_t> m_out;
  std::vector<std::uint8_t> m_scratch;
  bus::Ticks m_hold_time;
  bus::Ticks m_hold_deadline = bus::kNever;
  bool m_decided = false;  ///< a master has chosen a primary (alternation over)
  bus::Ticks m_tsprimary = 0;
  bus::Ticks m_alternate_at = bus::kNever;
  bool m_powered = false;
  bool m_swapped = false;  ///< Flying: interface 1 at A, interface 0 at A + 64
  std::function<void(const RedEvent&)> m_cb;
};

}  // namespace pbvbus::redundancy
