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
//   Request to the primary: acknowledged, no change. With the partner lost (counted by the
//   supervision or a switchover timeout): PRIMARY at once. A partner that has failed but is not
//   yet counted lost is taken for what it was before the failure (it failed silently).
//   Switchover request timeout: a partner that has failed silently (not yet counted lost by the
//   supervision) never answers; the requester waits `switch_timeout` (10 ms) after the
//   Primary_Request, then counts the partner lost (PartnerLost) and becomes PRIMARY (Prm_Cmd_Ack
//   as at a take-over). switch_timeout must exceed 2 × link_delay (else a live partner would be
//   overtaken: two primaries); the constructor throws std::invalid_argument otherwise.
// - Autonomous switchover (System Redundancy lets the slave switch on error, §G.1): when the
//   PRIMARY interface's engine leaves Data_Exch (watchdog expiry, new Set_Prm, ...) while the
//   partner's is in Data_Exch, it becomes BACKUP and sends take-over (1 × link_delay); when the
//   BACKUP notices its partner lost it becomes PRIMARY at once. No switch back after a repair:
//   a repaired interface starts in S_WAITING and the primary tells it to become BACKUP.
// - The IM's own switchover time (seeds-digest §2 S5, 000 L1832: the switchover time includes
//   "the changeover time of the DP slave interface"): with params.im_switchover_bound > 0, every
//   switchover after start-up (a PRIMARY existed since power-on) draws a time d uniformly in
//   [bound/2, bound] (draw_im_time(im_seed, n, bound), n = the station's switchover count) at its
//   trigger: the Primary_Request to a non-primary interface, the take-over of an autonomous
//   hand-over, or the backup counting the primary lost. The interface becomes PRIMARY at
//   max(the link steps above, trigger + d): until then it stays BP_SWITCHOVER (Red_State
//   Backup, §G.4 BP_* states), keeps answering Data_Exchange on its line, but its outputs do not
//   reach the backplane, which holds the last value (§G.1 "inputs and outputs are frozen during
//   the switchover"; S1), and no Prm_Cmd_Ack yet. The first Primary_Request after power-on is
//   not a switchover: at once, as before. im_switchovers() lists the draws.
// - Backplane outputs: only the PRIMARY interface's accepted Data_Exchange outputs (after its
//   engine applied them: Clear_Data and fail-safe zeros included) reach the backplane. When the
//   primary role is lost the outputs keep their last value until the new PRIMARY accepts its
//   first Data_Exchange, and at most Output_Hold_Time (from the last PrmCmd, else
//   `output_hold` = 1 s); then they go to the safe state (0) and stay there until fresh outputs
//   arrive (event OutputHoldExpired). The backup's outputs never reach the backplane.
//   Event FreshOutputs (iface = whose outputs) at the instant the backplane takes the first
//   accepted Data_Exchange outputs after start-up or after the primary role was lost or its
//   engine left Data_Exch (= the end of the hold, whether or not the hold had expired to 0):
//   "from the fault to the first fresh output on the new active channel" ends there.
// - Station power: power_off(now) is a dead station: both interfaces answer nothing (the owner
//   silences the FDL stations), the backplane drives nothing (outputs 0, no hold, no event),
//   link messages in flight are lost, roles Off, queued alarms are forgotten (volatile memory).
//   power_on(now) is a cold start as at the first power-on: both engines restart (Wait_Prm),
//   Prm_Cmd_Ack cleared, interface 0 S_PRIMARY, interface 1 S_WAITING, Tsprimary from 2 s. An
//   interface failed with fail_interface() stays FAILED across a power cycle (a defective IM is
//   not cured by switching off); repair_interface() is the way back.
// - DP-V1 alarms (S6, S8: interrupts only over the active channel, none lost): raise_alarm()
//   keeps the alarm in the station until the master acknowledges it through the interface that
//   is PRIMARY. It is raised on the PRIMARY interface's engine only (the backup's diagnosis never
//   carries it); with no PRIMARY (start-up, both failed, switchover in progress) or a PRIMARY
//   that cannot take it yet (not in Data_Exch with DP-V1, Alarm_Mode limit, type not enabled)
//   it waits in the station and is raised when one can. When the PRIMARY role moves before the
//   acknowledgement, the alarm is withdrawn from the old interface's engine and raised again on
//   the new PRIMARY (same type, slot, specifier bits, Add_Ack and data). The new engine assigns
//   its own Seq_Nr: acceptable, because a Seq_Nr only pairs an alarm with its Alarm_Ack within
//   ONE master-slave relation (§E.5), and the new PRIMARY's master has never seen the old
//   interface's number. The same happens when the PRIMARY's engine drops its alarms by leaving
//   Data_Exch (watchdog, re-parameterisation): raised again when it is back.
//   Withdrawal without a dp change: SlaveApplication has no call to remove an alarm, so the
//   station plays an internal Alarm_Ack (`5C slot type specifier` to SAP 50, from the engine's
//   owner) into the old engine; side effect: that engine's watchdog restarts at that instant
//   (as at any request from its owner) and its request counters count it. A
//   SlaveApplication::withdraw_alarm() would remove both.
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
  Off,           ///< the station has no power (power_off)
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
  /// BP_SWITCHOVER without the partner's take-over for this long → PRIMARY (> 2 × link_delay).
  bus::Ticks switch_timeout = 10 * bus::kTicksPerMs;
  bool autonomous_switchover = true;
  /// The IM's own switchover time T_SLAVE_UM (seeds-digest §2 S5; GSD
  /// Slave_Max_Switch_Over_Time): a switchover after start-up ends no earlier than a time drawn,
  /// per switchover, uniformly in [bound/2, bound] after its trigger (docs/switchover-timing.md
  /// "The IM's own time"). 0 = no IM time: the link steps only.
  bus::Ticks im_switchover_bound = 0;
  std::uint64_t im_seed = 0;  ///< seed of the draws (the scenario's seed and the address)
};

/// One switchover's IM time (RedundantSlave::im_switchovers()).
struct ImSwitchover {
  int iface = 0;              ///< the interface that becomes PRIMARY
  bus::Ticks trigger = 0;     ///< PrmCmd Primary_Request, take-over or partner loss
  bus::Ticks drawn = 0;       ///< the IM's time drawn for it (none recorded without a bound)
  bus::Ticks primary_at = bus::kNever;  ///< when it became PRIMARY (kNever: not (yet))
};

/// The IM time of the n-th switchover (n from 0) for `seed`: uniform in [bound/2, bound], tick
/// exact (splitmix64, the same on every platform).
bus::Ticks draw_im_time(std::uint64_t seed, std::uint64_t n, bus::Ticks bound);

struct RedEvent {
  enum class Kind : std::uint8_t {
    RoleChanged,
    PartnerLost,
    PartnerBack,
    OutputHoldExpired,
    AddressSwap,
    FreshOutputs,  ///< first accepted outputs after start-up or a primary change (end of hold)
  };
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
  /// The switchovers since construction with their drawn IM times, in trigger order.
  const std::vector<ImSwitchover>& im_switchovers() const { return m_im; }
  bus::Ticks output_hold_time() const { return m_hold_time; }

  void on_event(std::function<void(const RedEvent&)> cb) { m_cb = std::move(cb); }

  // DP-V1 alarms over the active channel (bus thread). Arguments as
  // dp::SlaveApplication::raise_alarm; BadArgument for a type or length the engine would refuse,
  // LimitExpired with kMaxStationAlarms unacknowledged, else Ok: kept until acknowledged
  // through the PRIMARY. *seq_nr is set when the alarm went into the PRIMARY's diagnosis at once.
  static constexpr std::size_t kMaxStationAlarms = 32;
  dp::AlarmResult raise_alarm(std::uint8_t type, std::uint8_t slot, dp::AlarmSpec spec,
                              bool add_ack, std::span<const std::uint8_t> data, bus::Ticks now,
                              std::uint8_t* seq_nr = nullptr);
  /// Alarms raised and not yet acknowledged through the PRIMARY.
  std::size_t alarms_outstanding() const { return m_alarms.size(); }
  /// Alarms acknowledged through the PRIMARY since construction.
  std::uint64_t alarms_acknowledged() const { return m_alarms_acked; }

  // Fault injection.
  void fail_interface(int i, bus::Ticks now);
  void repair_interface(int i, bus::Ticks now);

  void power_on(bus::Ticks now);
  /// Station power loss (both interfaces and the backplane); power_on() brings it back.
  void power_off(bus::Ticks now);
  bool powered() const { return m_powered; }
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
    bus::Ticks switch_deadline = bus::kNever;  ///< BP_SWITCHOVER: give up waiting for take-over
    Role failed_from = Role::SWaiting;  ///< the role before fail_interface(): what the partner
                                        ///< believes until it counts this interface lost
    bus::Ticks im_ready_at = bus::kNever;  ///< a switchover runs: PRIMARY no earlier than this
    bool im_wait = false;  ///< BP_SWITCHOVER only for the IM's time (take-over done)
    int im_index = -1;     ///< its entry in m_im
  };
  /// An alarm the station keeps until the PRIMARY's master acknowledges it.
  struct StationAlarm {
    std::uint8_t type = 0;
    std::uint8_t slot = 0;
    dp::AlarmSpec spec = dp::AlarmSpec::None;
    bool add_ack = false;
    std::vector<std::uint8_t> data;
    int iface = -1;           ///< the engine whose diagnosis carries it, -1 = waiting
    std::uint8_t seq = 0;     ///< the Seq_Nr that engine assigned
    std::uint64_t dx_entry = 0;  ///< that engine's data_exch_entries when raised there
  };

  dp::PrmCmdResult handle_prm_cmd(int i, const dp::PrmCmdView& v);
  void before_request(int i, bus::Ticks now);
  void after_request(int i, bus::Ticks now, std::uint64_t dx_before, std::uint64_t rs_before);
  void send(int from, Msg m, bus::Ticks now);
  void deliver(const LinkMsg& m, bus::Ticks now);
  void set_role(int i, Role r, bus::Ticks now);
  /// A switchover to interface i starts at `now` (the IM's time is drawn once per switchover).
  void start_im(int i, bus::Ticks now);
  /// PRIMARY now, or BP_SWITCHOVER until the IM's time is over.
  void become_primary(int i, bus::Ticks now);
  void check_primary_lost_master(bus::Ticks now);
  void lose_primary(bus::Ticks now);  ///< backplane: start the hold
  void take_outputs(int i, bus::Ticks now);  ///< FreshOutputs when it ends a hold/start-up
  void refresh_status();
  void set_ack(int i);
  /// Alarms: withdraw from non-PRIMARY engines, notice the ones an engine dropped, raise the
  /// waiting ones on the PRIMARY. After every request and every on_time() step.
  void sync_alarms(bus::Ticks now);
  void alarm_acked(int i, std::uint8_t type, std::uint8_t slot, std::uint8_t seq);
  void emit(RedEvent::Kind k, bus::Ticks at, int iface, Role from = Role::SWaiting,
            Role to = Role::SWaiting);
  bool alive(int i) const { return m_if[i].role != Role::Failed && m_if[i].role != Role::Off; }
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
  bool m_fresh_pending = false;  ///< the next outputs taken end a hold / the start-up
  std::vector<StationAlarm> m_alarms;
  std::uint64_t m_alarms_acked = 0;
  bool m_withdrawing = false;  ///< an internal Alarm_Ack is running: not the master's
  bool m_swapped = false;  ///< Flying: interface 1 at A, interface 0 at A + 64
  std::vector<ImSwitchover> m_im;
  std::function<void(const RedEvent&)> m_cb;
};

}  // namespace pbvbus::redundancy
