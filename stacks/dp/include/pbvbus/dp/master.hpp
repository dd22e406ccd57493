#pragma once
// DP master class 1 (IEC 61158-6 DP-V0/DP-V1 master, EN 50170 "DPM1"; protocol-facts.md §B.4,
// §D.1–§D.9, §E, §F): a sans-I/O fdl::InitiatorUser that sits on an FDL ActiveStation. It owns
// a list of configured slaves, brings each one up (Slave_Diag → Set_Prm → Chk_Cfg → Slave_Diag
// → Data_Exchange), polls them cyclically, evaluates their diagnosis, announces its operating
// state with Global_Control, runs sync/freeze groups, and offers MSAC_C1 read/write and alarm
// acknowledgement. FCB/FCV, retries and the "non-operational" marking are the FDL station's.
//
// Polling model. The station asks next_request() while it holds the token. The master walks its
// slaves in configuration order ("a pass"); a pass that the token hold time cuts short continues
// at the next token visit, and a new pass starts at the first token after a completed one. In a
// pass each slave gets at most: one "main" request (its next start-up step, a Data_Exchange, or a
// Slave_Diag retry), a Slave_Diag right after a DH answer, and one DP-V1 request. Everything goes
// as SRD high (Global_Control as SDN high), §B.4. A slave whose Min_Slave_Interval has not passed
// since its last main request is skipped in that pass.
//
// Decisions where the sources are silent (protocol-facts.md marks them [I]/[U]):
// - Operating states. Offline and Stop send nothing (slaves then fall back by their watchdog);
//   leaving Clear/Operate for Stop/Offline restarts every slave's start-up. In Clear, slaves
//   are started up and Data_Exchange runs with all-zero outputs, or with no output data for a
//   slave configured fail_safe. Global_Control carries `02 00` in Clear and `00 00` in Operate;
//   it goes out on every mode change and then whenever global_control_interval has passed
//   (default Data_Control_Time / 2, so that a token rotation of up to half of it still keeps
//   the "at least once per Data_Control_Time" rule). Sync/freeze commands carry the Clear_Data
//   bit of the current mode, because the slave takes Clear_Data from every Global_Control.
// - Auto_Clear: in Operate, the first slave that leaves data exchange (failure) switches the
//   master to Clear; it stays there until set_mode(Operate).
// - Start-up: one step per pass. Diag (step 2): no answer → station failure; Diag.Master_Add
//   neither 0xFF nor our address → Master_Lock (state Locked; the diag is re-read until the
//   slave is free); otherwise Set_Prm, whatever the faults shown (the ident is not compared:
//   a wrong one comes back as Prm_Fault). Set_Prm/Chk_Cfg expect SC (or an empty DL); RS or any
//   other status restarts the start-up. Diag after Chk_Cfg (step 5): Master_Add ≠ our address →
//   Locked; Prm_Fault, Cfg_Fault, Prm_Req or Not_Supported → start-up again from step 2;
//   Station_Not_Ready or Stat_Diag → read the diag again next pass; always-1 bit missing or fewer
//   than 6 octets → Invalid_Slave_Response, start-up again; else data exchange (Ext_Diag alone
//   does not block it).
// - Data_Exchange: the response must carry exactly the configured input length (SC = none);
//   otherwise Invalid_Slave_Response and a new start-up. DH → the inputs are taken and a
//   Slave_Diag follows at once. RS, UE, RR → the slave left data exchange: new start-up. NR →
//   no new inputs this cycle. A diagnosis read in data exchange that shows Not_Ready, Prm_Req,
//   Prm_Fault, Cfg_Fault or another master → new start-up; Stat_Diag → the diag is re-read each
//   pass without data exchange until it clears (no failure event).
// - Station failure: the first NoResponse of a slave not already failed, or a slave leaving
//   data exchange for any reason, raises StationFailure (S7: OB 86 W#16#39C4); reaching data
//   exchange again after that raises StationReturn. A slave that does not answer keeps state
//   NotPresent, its stored diagnosis is `01 00 00 FF idH idL` (Station_Non_Existent, ident from
//   the configuration), and its Slave_Diag is retried once per pass (at most every
//   failed_retry_interval). A return then runs the full start-up (re-parameterisation).
// - Diagnosis events: on every Slave_Diag read because of DH, and on any other read, while the
//   slave is in data exchange (or in Stat_Diag after it), whose octets differ from the stored
//   diagnosis. The reads of the start-up raise none (StationFailure/Return carry the diag).
// - DP-V1 (slave configured with DPV1_Enable in DPV1_Status_1): Read/Write go to slave SAP 51
//   from SSAP 51 and Alarm_Ack to SAP 50 from SSAP 51. An SC or empty DL answer means "not
//   ready": the master polls with an SRD without data on the same SAPs once per pass (§E.4)
//   until the response arrives or c1_response_timeout (10 ms units) has passed since the
//   request. One request is outstanding per slave; more are queued. Requests are accepted
//   only for a DP-V1 slave in data exchange, and fail (NotAvailable) when it leaves.
// - Alarms: in a DP-V1 slave's diagnosis a device-related block of ≥ 4 octets whose type octet
//   has bit 7 clear and is 1..126 is an alarm. Each alarm (type, slot, Seq_Nr) is reported once
//   (Alarm event) while it stays in the diagnosis; with auto_alarm_ack it is acknowledged at
//   once (`5C Slot Type Specifier`), else the user calls alarm_ack().
// - The API (set_mode, read, write, alarm_ack, global_control) is for the bus thread only, like
//   the callbacks it triggers; the process images (image()) may be used from any thread.
//
// Hot standby (docs/quantum-hsby-dp.md; ProSoft PTQ-PDPMV1 for Quantum Hot Standby, Beckhoff
// FC310x redundancy master). A master in standby sits on a passive (listen-only) ActiveStation
// at the same address as the active master of the pair and runs no requests. From the frames the
// station reports (on_observed) it shadows, per slave, whether the active master has it in data
// exchange (a Data_Exchange answered with the configured input length; out again by a Set_Prm,
// a Chk_Cfg, an RS/UE/RR or wrong-length answer, or a diagnosis showing Not_Ready, a fault,
// Prm_Req or another master), whether the Set_Prm/Chk_Cfg it saw carried exactly this master's
// parameters (unseen = assumed equal: both modules of a pair hold the same configuration), the
// outputs last sent (copied into image(): outputs continue from what the slaves hold; the
// application may overwrite them before the takeover), the inputs answered (published, but
// data_valid() stays false), and the last Global_Control. take_over(now) leaves standby: every
// slave the shadow saw in data exchange with our parameters goes straight to DataExchange (no
// Set_Prm/Chk_Cfg — a Set_Prm would take the slave out of data exchange and clear its outputs),
// no event; every other slave starts up normally. A resumed slave whose first Data_Exchange is
// not answered as expected starts up normally too (the usual failure handling and events).
// Global_Control is owed at once only if the last one seen did not announce our mode; otherwise
// its interval runs on from the one seen. The station is switched separately:
// ActiveStation::set_passive(false, now) right after take_over(now).
//
// Equidistance (constant bus cycle time, docs/dp-equidistance.md): with equidistant_cycle
// T_DP > 0 a pass does not start at a token receipt but when next_request() is asked at or
// after its due time; between passes pause_until() asks the station to keep the token until
// then. The first pass after power-on or a restart from Stop/Offline sets the grid origin;
// a pass starting after its due time is an overrun (lateness = start − due); the next one is
// due at the first grid point after the start.
//
// Performance: the steady Data_Exchange path does not allocate (the Request's data vector keeps
// its capacity, cycle statistics use a fixed ring).

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/dp/cfg_identifier.hpp"
#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/dpv1_pdu.hpp"
#include "pbvbus/dp/master_acyclic.hpp"
#include "pbvbus/dp/master_image.hpp"
#include "pbvbus/dp/prm.hpp"
#include "pbvbus/dp/sap.hpp"
#include "pbvbus/dp/slave_config.hpp"
#include "pbvbus/fdl/station.hpp"

namespace pbvbus::dp {

/// Master operating states (§D.9).
enum class MasterMode : std::uint8_t { Offline, Stop, Clear, Operate };
std::string_view to_string(MasterMode m);

/// Global_Control Control_Command bits (§D.6).
inline constexpr std::uint8_t kGcClearData = 0x02;
inline constexpr std::uint8_t kGcUnfreeze = 0x04;
inline constexpr std::uint8_t kGcFreeze = 0x08;
inline constexpr std::uint8_t kGcUnsync = 0x10;
inline constexpr std::uint8_t kGcSync = 0x20;

/// One configured slave (what a configuration tool puts into the master's database).
struct SlaveParams {
  std::uint8_t address = 0;  ///< 0..125
  std::string name;          ///< for reports
  std::uint16_t ident = 0;
  // Set_Prm (§D.2).
  std::uint8_t station_status = kPrmLockReq | kPrmWdOn;  ///< add kPrmSyncReq/kPrmFreezeReq for groups
  std::uint8_t wd_fact_1 = 10;
  std::uint8_t wd_fact_2 = 10;
  std::uint8_t min_tsdr = 11;  ///< t_bit; 0 = leave unchanged
  std::uint8_t group_ident = 0;
  std::vector<std::uint8_t> user_prm;  ///< octets 8.., incl. DPV1_Status_1..3 for DP-V1
  // Chk_Cfg (§D.3): one entry per module, its identifier octets.
  std::vector<SlaveModule> modules;
  std::uint16_t min_slave_interval = 1;  ///< 100 µs units (GSD Min_Slave_Intervall)
  bool fail_safe = false;                ///< send no output data in Clear (GSD Fail_Safe)
  std::uint16_t c1_response_timeout = 100;  ///< 10 ms units (GSD C1_Response_Timeout)
  bool active = true;  ///< false: never addressed (diag shows Deactivated)
  /// PI 2.212 slave redundancy: an 8-octet PrmCmd block (structured, type 0x02) appended to
  /// Set_Prm after user_prm, with DPV1_Status_3 |= PrmCmd | Prm_Structure (0x88). Empty = none.
  /// The dp layer carries the octets; redundancy::MasterSystem decides what they say.
  std::vector<std::uint8_t> prm_cmd;

  bool dpv1() const { return user_prm.size() >= 3 && (user_prm[0] & kDpv1Enable) != 0; }
  std::vector<std::uint8_t> set_prm_du() const;
  std::vector<std::uint8_t> chk_cfg_du() const;
};

struct MasterParams {
  std::uint8_t address = 1;
  std::uint16_t data_control_time = 12;  ///< 10 ms units
  bool auto_clear = false;
  bool auto_alarm_ack = true;
  MasterMode initial_mode = MasterMode::Operate;
  bus::Ticks global_control_interval = 0;  ///< 0 = Data_Control_Time / 2
  bus::Ticks failed_retry_interval = 0;    ///< minimum time between Slave_Diag retries of an
                                           ///< absent or locked slave; 0 = once per pass
  bool standby = false;                    ///< start in hot standby (see set_standby())
  /// Equidistance (constant bus cycle time T_DP, docs/dp-equidistance.md); 0 = off.
  bus::Ticks equidistant_cycle = 0;
};

/// Equidistance counters (docs/dp-equidistance.md). A cycle is a pass over the slaves; it is due
/// at origin + k·T_DP (origin = the first pass after power-on or a restart from Stop/Offline).
struct EquidistanceStats {
  bus::Ticks period = 0;          ///< T_DP; 0 = equidistance off
  std::uint64_t cycles = 0;       ///< passes started
  std::uint64_t overruns = 0;     ///< passes started after their due time
  std::uint64_t missed = 0;       ///< due times passed over entirely by a late pass
  bus::Ticks max_lateness = 0;    ///< largest start − due time
  bus::Ticks last_lateness = 0;   ///< of the last overrun
  bus::Ticks last_start = bus::kNever;
  /// Measured start jitter: max − min of the intervals between consecutive pass starts that
  /// are both on time (0 while the grid holds).
  bus::Ticks jitter = 0;
  bus::Ticks interval_min = 0;
  bus::Ticks interval_max = 0;
  std::uint64_t intervals = 0;    ///< intervals that went into the jitter
};

/// Counters of the hot-standby takeovers (see the header comment).
struct HsbyStats {
  std::uint64_t takeovers = 0;
  std::uint64_t resumed = 0;    ///< slaves whose first Data_Exchange after a takeover succeeded
  std::uint64_t restarted = 0;  ///< slaves started up after a takeover (not in DX in the shadow,
                                ///< or their first Data_Exchange failed)
  std::uint64_t frames_observed = 0;  ///< frames reported while in standby
  std::uint64_t dx_observed = 0;      ///< the active master's completed Data_Exchange cycles
};

/// The master's view of a slave.
enum class SlaveStatusState : std::uint8_t {
  Inactive,      ///< master in Stop/Offline, or the slave is deactivated
  Diag,          ///< start-up step 2: reading the diagnosis
  Prm,           ///< start-up step 3: Set_Prm
  Cfg,           ///< start-up step 4: Chk_Cfg
  CheckDiag,     ///< start-up step 5 (or Stat_Diag in data exchange): reading the diagnosis
  DataExchange,
  NotPresent,    ///< no answer: Slave_Diag retried
  Locked,        ///< parameterised by another master: Slave_Diag retried
};
std::string_view to_string(SlaveStatusState s);

struct MasterSlaveStats {
  std::uint64_t requests = 0;
  std::uint64_t data_exchanges = 0;   ///< successful Data_Exchange cycles
  std::uint64_t diag_reads = 0;
  std::uint64_t startups = 0;         ///< Set_Prm sent
  std::uint64_t failures = 0;         ///< StationFailure events
  std::uint64_t returns = 0;          ///< StationReturn events
  std::uint64_t retries = 0;          ///< FDL repeats of requests to this slave
  std::uint64_t no_response = 0;
  std::uint64_t invalid_responses = 0;
  std::uint64_t dh = 0;               ///< DH answers
  std::uint64_t alarms = 0;
  std::uint64_t alarm_acks = 0;       ///< positive Alarm_Ack responses
  std::uint64_t prm_cmds = 0;         ///< pure PrmCmd Set_Prms acknowledged in data exchange
  // DP cycle: time between two consecutive Data_Exchange polls (request starts) of the slave.
  std::uint64_t cycle_count = 0;
  bus::Ticks cycle_min = 0;
  bus::Ticks cycle_max = 0;
  bus::Ticks cycle_last = 0;
};

/// Something the scenario layer may put into the event stream.
struct MasterEvent {
  enum class Kind : std::uint8_t {
    StationFailure,  ///< S7: OB 86 W#16#39C4
    StationReturn,   ///< S7: OB 86 W#16#38C4
    Diagnosis,       ///< a Slave_Diag was read (see the rules above)
    Alarm,           ///< a DP-V1 alarm in the diagnosis (S7: OB 82/OB 40/...)
    ModeChange,      ///< the master changed its operating state (e.g. Auto_Clear)
    DataExchangeEntered,  ///< the slave reached data exchange (every start-up, after any
                          ///< StationReturn); no S7 event of its own
    PrmCmdDone,      ///< a pure PrmCmd Set_Prm was acknowledged (the slave stays in DX)
    AlarmAcknowledged,  ///< a positive Alarm_Ack response (alarm_type/slot/specifier as sent)
  };
  enum class Cause : std::uint8_t {
    None,
    NoResponse,        ///< the slave does not answer
    LeftDataExchange,  ///< RS, or the diagnosis shows it is no longer ours / not ready
    InvalidResponse,   ///< implausible answer
  };
  Kind kind = Kind::Diagnosis;
  bus::Ticks time = 0;
  std::uint8_t slave = 0;
  Cause cause = Cause::None;
  MasterMode mode = MasterMode::Operate;   ///< ModeChange
  std::span<const std::uint8_t> diag;      ///< Diagnosis/Alarm: the whole Slave_Diag DU
  std::uint8_t alarm_type = 0;             ///< Alarm
  std::uint8_t alarm_slot = 0;
  std::uint8_t alarm_specifier = 0;
  std::span<const std::uint8_t> alarm_data;  ///< Alarm: octets after the specifier
};
std::string_view to_string(MasterEvent::Kind k);
std::string_view to_string(MasterEvent::Cause c);
using MasterEventHandler = std::function<void(const MasterEvent&)>;

class Master final : public fdl::InitiatorUser {
 public:
  static constexpr std::size_t kCycleSamples = 1024;

  /// Throws std::invalid_argument for an unusable configuration (address out of range or
  /// twice, equal to the master's, bad identifiers, more than 244 octets each way, user prm
  /// too long, zero watchdog factors with WD_On).
  Master(MasterParams params, std::vector<SlaveParams> slaves);
  Master(const Master&) = delete;
  Master& operator=(const Master&) = delete;

  const MasterParams& params() const { return m_p; }
  std::uint8_t address() const { return m_p.address; }

  // --- operating state ---
  MasterMode mode() const { return m_mode; }
  void set_mode(MasterMode m);
  /// Queues a Global_Control broadcast (Sync/Unsync/Freeze/Unfreeze bits) for `group_select`
  /// (0 = all slaves); it goes out at the start of the next pass.
  void global_control(std::uint8_t command, std::uint8_t group_select);

  // --- slaves ---
  std::size_t slave_count() const { return m_slaves.size(); }
  bool has_slave(std::uint8_t address) const { return address < 128 && m_index[address] >= 0; }
  const SlaveParams& slave_params(std::uint8_t address) const;
  SlaveStatusState slave_state(std::uint8_t address) const;
  /// Last diagnosis as stored by the master (incl. the master-set bits).
  std::span<const std::uint8_t> slave_diag(std::uint8_t address) const;
  const MasterSlaveStats& slave_stats(std::uint8_t address) const;
  /// Median DP cycle time of the slave over the last kCycleSamples cycles (0 if none).
  bus::Ticks cycle_median(std::uint8_t address) const;
  MasterImage& image(std::uint8_t address);
  const MasterImage& image(std::uint8_t address) const;
  std::vector<std::uint8_t> addresses() const;

  void set_event_handler(MasterEventHandler h) { m_events = std::move(h); }

  /// PI 2.212: replaces the slave's PrmCmd block (8 octets, SlaveParams::prm_cmd must have been
  /// configured) for every later Set_Prm, and sends it at once as a "pure PrmCmd" Set_Prm
  /// (7-octet header + DPV1_Status_1..3 + the block = 18 octets, the VPC3's PRM_CMD_LENGTH,
  /// protocol-facts.md §G.2) as the slave's next main request if it is in data exchange or
  /// further in its start-up than the Set_Prm step (a start-up Set_Prm not yet sent carries the
  /// new block anyway). The pure PrmCmd keeps the slave in data exchange: an SC/empty answer →
  /// event PrmCmdDone; any other answer restarts the slave's start-up; no answer is a station
  /// failure as for any request. Returns false (nothing changes) for an unknown slave, a slave
  /// without a configured PrmCmd block or a block that is not 8 octets. With send = false the
  /// block only replaces the stored one (what a later start-up's Set_Prm will carry).
  bool prm_cmd(std::uint8_t address, std::span<const std::uint8_t> block, bool send = true);
  /// Whether a pure PrmCmd for the slave is waiting to be sent.
  bool prm_cmd_pending(std::uint8_t address) const;

  /// Deactivates (active = false) or activates a configured slave at run time, as S7's SFC 12
  /// D_ACT_DP does (master_activate.cpp, docs/s7cpu.md "DP system functions"): a deactivated
  /// slave is no longer addressed (state Inactive, stored diagnosis Deactivated, its DP-V1 jobs
  /// fail, its inputs invalid), without a StationFailure event; an activated one runs the full
  /// start-up again (Slave_Diag, Set_Prm, Chk_Cfg, ...) while the master is in Clear/Operate.
  /// Returns false for an unknown slave; true (nothing changes) when it already is so.
  bool set_slave_active(std::uint8_t address, bool active);

  // --- DP-V1 MSAC_C1 (bus thread). Each returns an id (> 0) or 0 if refused: unknown slave, not
  // DP-V1, not in data exchange, or a length out of 1..240. The callback runs on completion.
  std::uint32_t read(std::uint8_t address, std::uint8_t slot, std::uint8_t index,
                     std::uint8_t length, AcyclicCallback cb);
  std::uint32_t write(std::uint8_t address, std::uint8_t slot, std::uint8_t index,
                      std::span<const std::uint8_t> data, AcyclicCallback cb);
  std::uint32_t alarm_ack(std::uint8_t address, std::uint8_t slot, std::uint8_t type,
                          std::uint8_t specifier, AcyclicCallback cb);

  // --- hot standby (see the header comment) ---
  /// Enter or leave standby. Entering keeps the master's own view of each slave as the start of
  /// the shadow; leaving through set_standby(false) is take_over(m_now).
  void set_standby(bool on);
  bool standby() const { return m_standby; }
  /// Leave standby and resume the slaves the shadow saw in data exchange.
  void take_over(bus::Ticks now);
  /// Whether the shadow currently sees the slave in data exchange with the active master.
  bool shadow_in_dx(std::uint8_t address) const;
  const HsbyStats& hsby_stats() const { return m_hsby; }

  // --- equidistance (docs/dp-equidistance.md) ---
  const EquidistanceStats& equidistance() const { return m_eq; }

  // --- fdl::InitiatorUser ---
  void on_power_on(bus::Ticks now) override;
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override;
  void on_confirmation(const fdl::Confirmation& con) override;
  void on_token(bus::Ticks now, bus::Ticks trr) override;
  void on_observed(bus::Ticks now, const fdl::Telegram& t) override;
  bus::Ticks pause_until(bus::Ticks now) override;

 private:
  enum class Kind : std::uint8_t { None, GlobalControl, Diag, Prm, Cfg, DataExchange, Acyclic, PrmCmd };
  struct Job {
    std::uint32_t id = 0;
    std::uint8_t fn = 0;
    std::uint8_t sap = kSapC1ReadWrite;
    std::uint8_t slot = 0;
    std::uint8_t index = 0;
    std::uint8_t length = 0;  ///< Read: wanted; Write: data length; Alarm_Ack: specifier
    std::vector<std::uint8_t> pdu;
    bool sent = false;        ///< request delivered; polling for the answer
    bool internal = false;    ///< automatic Alarm_Ack
    bus::Ticks deadline = bus::kNever;
    AcyclicCallback cb;
  };
  struct AlarmKey {
    std::uint8_t type = 0;
    std::uint8_t slot = 0;
    std::uint8_t seq = 0;
    bool operator==(const AlarmKey&) const = default;
  };
  struct Slave {
    SlaveParams p;
    SlaveLayout layout;
    std::vector<std::uint8_t> prm;
    std::vector<std::uint8_t> cfg;
    bool prm_cmd_due = false;  ///< a pure PrmCmd Set_Prm is owed (see prm_cmd())
    std::unique_ptr<MasterImage> image;
    SlaveStatusState state = SlaveStatusState::Inactive;
    bool failed = false;
    bool in_dx = false;           ///< reached data exchange since the last start-up
    bus::Ticks min_interval = 0;
    bus::Ticks last_main = bus::kNever;  ///< start of the last main request
    bus::Ticks last_dx = bus::kNever;    ///< start of the last Data_Exchange
    bus::Ticks last_retry = bus::kNever;
    // Within the current pass.
    bool turn_main = false;
    bool turn_diag = false;
    bool turn_acyclic = false;
    bool diag_after_dh = false;
    std::vector<std::uint8_t> diag;  ///< stored diagnosis
    std::vector<AlarmKey> alarms_seen;
    std::deque<Job> jobs;
    MasterSlaveStats stats;
    std::array<bus::Ticks, kCycleSamples> cycles{};
    std::size_t cycle_pos = 0;
    // Hot-standby shadow of the active master's view (master_hsby.cpp).
    bool sh_dx = false;
    bool sh_prm_ok = true;
    bool sh_cfg_ok = true;
    bool probe = false;  ///< resumed at a takeover, first Data_Exchange not yet answered
  };

  Slave& slave(std::uint8_t address);
  const Slave& slave(std::uint8_t address) const;
  bool build_for_slave(Slave& s, bus::Ticks now, fdl::Request& out);
  bool main_request(Slave& s, bus::Ticks now, fdl::Request& out);
  void fill(fdl::Request& out, const Slave& s, std::optional<std::uint8_t> dsap,
            std::optional<std::uint8_t> ssap, Kind kind);
  void start_pass();
  /// Equidistance: starts the pass if its due time has come (master_equidistance.cpp).
  bool equidistant_start(bus::Ticks now);

  void on_diag(Slave& s, const fdl::Confirmation& con, bool after_dh);
  void on_dx(Slave& s, const fdl::Confirmation& con);
  void on_acyclic(Slave& s, const fdl::Confirmation& con);
  void no_response(Slave& s, bus::Ticks now);
  /// Back to start-up step 2; raises StationFailure if the slave was in data exchange.
  void restart(Slave& s, bus::Ticks now, MasterEvent::Cause cause);
  void enter_dx(Slave& s, bus::Ticks now);
  void failure_event(Slave& s, bus::Ticks now, MasterEvent::Cause cause);
  void store_diag(Slave& s, std::span<const std::uint8_t> du, std::uint8_t extra_status_1,
                  bus::Ticks now, bool force_event);
  void evaluate_alarms(Slave& s, bus::Ticks now);
  void finish_job(Slave& s, AcyclicStatus st, bus::Ticks now, Dpv1Error err = {},
                  std::span<const std::uint8_t> data = {});
  void fail_jobs(Slave& s, bus::Ticks now);
  std::uint32_t queue_job(std::uint8_t address, Job job);
  void reset_slaves();
  void reset_shadow();
  void shadow_request(bus::Ticks now, const fdl::Telegram& t);
  void shadow_reply(Slave& s, Kind kind, const fdl::Telegram& t);
  void probe_done(Slave& s, bool ok);
  void emit(const MasterEvent& e) {
    if (m_events) m_events(e);
  }

  MasterParams m_p;
  std::vector<Slave> m_slaves;
  std::array<int, 128> m_index{};
  MasterMode m_mode = MasterMode::Operate;
  MasterEventHandler m_events;
  bus::Ticks m_now = 0;
  bus::Ticks m_gc_interval = 0;

  // Global_Control.
  bool m_gc_due = true;  ///< mode announcement owed now
  bus::Ticks m_last_gc = bus::kNever;
  std::deque<std::array<std::uint8_t, 2>> m_gc_queue;

  // Pass over the slaves.
  bool m_pass_active = false;
  bool m_pass_fresh = false;  ///< no slave request sent yet in this pass
  std::size_t m_cursor = 0;

  // The request on the wire.
  Kind m_out_kind = Kind::None;
  int m_out_slave = -1;
  bool m_out_dh_diag = false;

  // Hot standby.
  bool m_standby = false;
  HsbyStats m_hsby;
  int m_sh_slave = -1;  ///< slave of the last observed request, awaiting its answer
  Kind m_sh_kind = Kind::None;
  bool m_sh_gc_seen = false;
  bool m_sh_gc_clear = false;
  bus::Ticks m_sh_gc_at = bus::kNever;

  // Equidistance.
  EquidistanceStats m_eq;
  bus::Ticks m_eq_due = bus::kNever;  ///< due time of the next pass; kNever = no grid yet
  bool m_eq_last_late = true;         ///< the last pass started late (or is the first)

  std::uint32_t m_next_job_id = 1;
  std::vector<std::uint8_t> m_scratch;
};

}  // namespace pbvbus::dp
