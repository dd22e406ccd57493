#pragma once
// The DP slave engine (IEC 61158-6 DP-V0/DP-V1 slave; protocol-facts.md §B.4, §D, §E, §F): a
// sans-I/O fdl::ResponderUser that sits on an FDL PassiveStation. It implements the slave
// state machine Power_On / Wait_Prm / Wait_Cfg / Data_Exch, Set_Prm and Chk_Cfg checking, the
// diagnosis, the watchdog, locking by a master, Global_Control (Clear_Data, Sync/Unsync,
// Freeze/Unfreeze, groups), Set_Slave_Add, Rd_Inp/Rd_Outp, MSAC_C1 read/write and alarms, and
// MSAC_C2 connections. The device side is SlaveApplication (thread-safe).
//
// Decisions where the sources are silent (protocol-facts.md marks them [I]/[U]):
// - Locking. After a locking Set_Prm the owner is Diag.Master_Add. A Set_Prm or Chk_Cfg from
//   another master is answered SC and has no effect (the FDL acknowledges; the DP layer ignores
//   it); that master reads Slave_Diag, sees another owner and derives Master_Lock. A
//   Data_Exchange or a unicast Global_Control from another master gets RS (the
//   default SAP and SAP 58 are open only to the owner); a broadcast Global_Control from another
//   master is ignored. Slave_Diag, Get_Cfg, Rd_Inp and Rd_Outp answer anyone.
// - Set_Prm is always answered SC (except at address 126, where it gets RS: a slave without a
//   valid address cannot be parameterised). Lock=0/Unlock=0 only changes min TSDR. Unlock=1 from
//   the owner releases the slave (back to Wait_Prm, outputs safe). A good locking Set_Prm in
//   Data_Exch goes to Wait_Cfg (a Chk_Cfg must follow). A bad one (length, ident, WD factor 0,
//   user prm length/content, DPV1_Status bits the slave does not support) sets Prm_Fault; an
//   unsupported Sync_Req/Freeze_Req sets Not_Supported; either way the slave is in Wait_Prm,
//   unlocked. Fault flags are cleared by the next good Set_Prm (Cfg_Fault too).
// - PrmCmd (PI 2.212 slave redundancy, §G.2; needs SlaveFeatures::prm_cmd and prm_structure):
//   a structured block of type 0x02 must be exactly 8 octets, at most one per Set_Prm, and
//   needs DPV1_Status_3 PrmCmd; otherwise Prm_Fault. After every other check has passed the
//   block goes to SlaveConfig::on_prm_cmd (Reject = Prm_Fault). A "pure PrmCmd" is a Set_Prm
//   of exactly 18 octets (7 + DPV1_Status_1..3 + one PrmCmd block; the VPC3 PRM_CMD_LENGTH,
//   whose value the sources do not give) with Lock_Req, PrmCmd and Prm_Structure, from the
//   owner of a slave in Wait_Cfg or Data_Exch: the header and DPV1_Status octets are not
//   evaluated again, the state, outputs and watchdog factors stay, and only the block goes to
//   on_prm_cmd (PrmCmdView::pure). The same 18 octets to an unparameterised slave are an
//   ordinary Set_Prm. The engine never interprets the block; a redundancy layer does.
// - Chk_Cfg is accepted in Wait_Cfg and Data_Exch (RS in Power_On/Wait_Prm). Identifiers are
//   compared by meaning (cfg_identifier.hpp). A mismatch sets Cfg_Fault, lists the faulty
//   modules in an identifier-related block, and returns the slave to Wait_Prm, unlocked.
// - Data_Exchange with an output length other than the configured one (or zero with Fail_Safe)
//   is a parameterisation error: outputs go safe, the slave returns to Wait_Prm (Prm_Req) and
//   answers RS, so the master re-parameterises. With Fail_Safe support a zero-length output
//   telegram sets the outputs to the safe state (zero) and is answered normally.
// - Clear_Data sets the outputs to the safe state and holds them there until a Global_Control
//   without Clear_Data; received outputs are still stored (Rd_Outp shows them).
// - DH is answered to the owner's Data_Exchange while a diagnosis change made by the application
//   (or a new alarm, a status PDU, SlaveApplication::request_diag_read()) has not yet been read
//   by the owner with Slave_Diag. State changes the master
//   caused itself (Set_Prm, Chk_Cfg, Global_Control) do not count as new diagnosis.
// - Ext_Diag is set while the application says so, or channel diagnoses, module faults or a
//   Cfg_Fault identifier block are present. Alarm and status PDUs alone do not set it.
// - DP-V1 alarms: every outstanding (unacknowledged) alarm is in each diagnosis, oldest first.
//   Alarm_Ack with no matching alarm (slot, type, Seq_Nr) gets `DC 80 B5 00` (state conflict).
// - MSAC_C1 (SAP 51, SAP 50) is open only in Data_Exch with DPV1_Enable, to the owner; else RS.
//   A record handler that answers at once is answered in the same SRD; a pending one gets SC and
//   its result goes out on the master's poll (an SRD with no data, §E.4); polls before that get
//   SC. A new request replaces a pending one. Unknown (slot, index): `80 B0 00` (invalid index);
//   a slot beyond the modules with no handler: `80 B2 00` (invalid slot); other function
//   numbers: `80 A9 00` (feature not supported).
// - MSAC_C2: an Initiate.req to the resource manager (SAP 49) reserves a connection SAP (48
//   downward) and is answered `56 SAP Send_Timeout`; no free SAP → `D7 80 C3 00`. The Initiate
//   on that SAP is answered Initiate.res+ (Max_Len_Data_Unit 240, Features_Supported_1 = 0x01
//   (read/write), profile fields echoed, the source and destination address data swapped).
//   Idle or an empty SRD is a poll. Abort closes it (SC). 2 × Send_Timeout (10 ms units)
//   without a frame closes it; requests on a closed connection SAP get RS.
// - Set_Slave_Add is answered SC with Reply::new_address when it succeeds (supported, Power_On
//   or Wait_Prm, ident matches, address 0..125, no earlier No_Add_Chg); otherwise RS.
// - The watchdog is restarted by every frame from the owner (any SAP, broadcast included). On
//   expiry: outputs safe, Wait_Prm, unlocked; the diagnosis is then `02 05 00 FF idH idL`.
//
// - Statistics (SlaveStats, stats()): every request that reaches the engine counts under its
//   service, whatever the answer and whoever sent it; FCB repeats are answered by the FDL
//   station from its stored reply and never reach the engine, so they do not count (a master
//   counting the requests it got an answer to sees the same numbers). Counters run from
//   construction; power cycles do not reset them.
//
// - Mutations (SlaveConfig::mutation, test-only; devices/slave_mutant.hpp, docs/mutants.md):
//   each breaks one rule at the one place that rule is implemented here and leaves the rest
//   alone. Notable choices: IgnoreWatchdog still reports WD_On (only the expiry is gone) and
//   never asks for a timer; IgnoreFreeze/IgnoreSync still set Freeze_Mode/Sync_Mode in the
//   diagnosis; KeepStateOnPowerCycle also restarts the watchdog at power-on (so the kept state
//   survives a power-off longer than the watchdog); SlowSlaveInterval measures from the last
//   Data_Exchange it answered (an ignored request does not make the ASIC busy) and stays silent
//   (Reply::None; an FCB repeat of it is silent too); TearConsistent swaps the first half
//   (in_len / 2 octets) of each consistent module with the image of the previous
//   Data_Exchange; Dpv1BadIndexAccepted answers a Read of an unknown index in an existing slot
//   with the requested length of zero octets (Writes and unknown slots keep their error).
//
// Performance: the Data_Exchange path does not allocate (fixed buffers; Reply::data keeps its
// capacity when the station reuses its Reply).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/prm.hpp"
#include "pbvbus/dp/sap.hpp"
#include "pbvbus/dp/slave_application.hpp"
#include "pbvbus/dp/slave_config.hpp"
#include "pbvbus/fdl/station.hpp"

namespace pbvbus::dp {

/// What the slave was asked and what became of it (the slave's own view, for reports). Each
/// request counts once under its service (see the header comment for repeats).
struct SlaveStats {
  std::uint64_t set_prm = 0;         ///< Set_Prm (SAP 61)
  std::uint64_t chk_cfg = 0;         ///< Chk_Cfg (SAP 62)
  std::uint64_t slave_diag = 0;      ///< Slave_Diag (SAP 60)
  std::uint64_t data_exchange = 0;   ///< Data_Exchange (default SAP, SRD)
  std::uint64_t global_control = 0;  ///< Global_Control (SAP 58), unicast or broadcast
  std::uint64_t get_cfg = 0;         ///< Get_Cfg (SAP 59)
  std::uint64_t rd_inp = 0;          ///< Rd_Inp (SAP 56)
  std::uint64_t rd_outp = 0;         ///< Rd_Outp (SAP 57)
  std::uint64_t set_slave_add = 0;   ///< Set_Slave_Add (SAP 55)
  std::uint64_t dpv1 = 0;            ///< MSAC_C1 and MSAC_C2 (SAPs 0..51)
  std::uint64_t other = 0;           ///< any other SAP or function (answered RS)
  /// Of the requests above, those answered RS (wrong state, locked by another master,
  /// service not supported, SAP closed).
  std::uint64_t refused = 0;
  std::uint64_t prm_faults = 0;         ///< Set_Prm that left Prm_Fault or Not_Supported set
  std::uint64_t cfg_faults = 0;         ///< Chk_Cfg that did not match the real configuration
  std::uint64_t data_exch_entries = 0;  ///< transitions into Data_Exch
  std::uint64_t watchdog_expiries = 0;  ///< response monitoring ran out (back to Wait_Prm)
};

class SlaveEngine final : public fdl::ResponderUser {
 public:
  /// Throws std::invalid_argument if the configuration is unusable (see build_layout()).
  explicit SlaveEngine(SlaveConfig cfg);
  SlaveEngine(const SlaveEngine&) = delete;
  SlaveEngine& operator=(const SlaveEngine&) = delete;

  SlaveApplication& application() { return m_app; }
  const SlaveConfig& config() const { return m_cfg; }
  const SlaveLayout& layout() const { return m_layout; }

  // Bus-thread view of the state (tests, reports).
  SlaveState state() const { return m_state; }
  std::uint8_t master_address() const { return m_master; }
  std::uint8_t group_ident() const { return m_group; }
  bool sync_mode() const { return m_sync_mode; }
  bool freeze_mode() const { return m_freeze_mode; }
  bool watchdog_on() const { return m_wd_on; }
  bus::Ticks watchdog_time() const { return m_wd_ticks; }
  const Dpv1Status& dpv1_status() const { return m_dpv1; }
  /// Counters since construction (see SlaveStats).
  const SlaveStats& stats() const { return m_stats; }
  /// The inputs sent in the last Data_Exchange reply (zeros before the first one).
  std::span<const std::uint8_t> last_inputs() const { return {m_inputs.data(), m_layout.inputs}; }
  /// The output octets of the last Data_Exchange request accepted (zeros before the first one;
  /// kept after the slave leaves data exchange, unlike the outputs applied to the device).
  std::span<const std::uint8_t> last_outputs() const {
    return {m_last_rx.data(), m_layout.outputs};
  }
  /// Forgets a No_Add_Chg (the "factory reset" that allows Set_Slave_Add again).
  void factory_reset() { m_no_add_chg = false; }
  /// The Slave_Diag DU the slave would send now.
  std::span<const std::uint8_t> current_diag();

  // fdl::ResponderUser
  void on_power_on(bus::Ticks now) override;
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override;
  bus::Ticks next_deadline() const override;
  void on_time(bus::Ticks now) override;

 private:
  struct PendingRecord {
    bool active = false;
    std::uint32_t id = 0;
    std::uint8_t fn = 0;
    std::uint8_t slot = 0;
    std::uint8_t index = 0;
    std::uint8_t length = 0;
  };
  struct C2Connection {
    enum class St : std::uint8_t { Closed, Reserved, Open };
    St st = St::Closed;
    std::uint8_t master = 0;
    bus::Ticks timeout = 0;  ///< 2 × Send_Timeout
    bus::Ticks deadline = bus::kNever;
    PendingRecord pending;
  };

  void check_timers(bus::Ticks now);
  void count_request(std::uint8_t dsap);
  void handle_set_prm(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_chk_cfg(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_slave_diag(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_data_exchange(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_global_control(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_set_slave_add(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_rd_inp(fdl::Reply& reply);
  void handle_rd_outp(fdl::Reply& reply);
  void handle_c1_read_write(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_c1_alarm(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_c2_rm(const fdl::Indication& ind, fdl::Reply& reply);
  void handle_c2_conn(C2Connection& c, const fdl::Indication& ind, fdl::Reply& reply);
  /// Runs a Read/Write request through the handlers; fills the reply or marks it pending.
  void record_request(std::span<const std::uint8_t> pdu, std::uint8_t master, bool c2,
                      PendingRecord& pending, fdl::Reply& reply);
  /// Answers a poll: the completed result of `pending`, or SC.
  void record_poll(PendingRecord& pending, fdl::Reply& reply);

  void enter_data_exchange();
  /// Leaves Data_Exch/Wait_Cfg: outputs safe, modes and DP-V1 alarm state reset.
  void leave_operation();
  void go_wait_prm();
  void set_state(SlaveState s);
  void set_outputs_safe();
  void apply_outputs();
  void snapshot_inputs(std::span<std::uint8_t> out);
  void build_diag();
  bool mutated(EngineMutation m) const { return m_cfg.mutation == m; }
  /// TearConsistent: the first half of every consistent module from the previous image.
  void tear_inputs();

  SlaveConfig m_cfg;
  SlaveLayout m_layout;
  SlaveApplication m_app;

  SlaveState m_state = SlaveState::WaitPrm;
  std::uint8_t m_master = kNoMaster;
  std::uint8_t m_group = 0;
  bool m_prm_fault = false;
  bool m_cfg_fault = false;
  bool m_not_supported = false;
  std::vector<std::uint16_t> m_cfg_fault_modules;
  std::size_t m_cfg_fault_span = 0;
  bool m_wd_on = false;
  bus::Ticks m_wd_ticks = 0;
  bus::Ticks m_wd_deadline = bus::kNever;
  bool m_sync_enabled = false;
  bool m_freeze_enabled = false;
  bool m_sync_mode = false;
  bool m_freeze_mode = false;
  bool m_clear = false;
  bool m_fail_safe_zero = false;  ///< last Data_Exchange carried zero-length outputs (Fail_Safe)
  Dpv1Status m_dpv1;
  bool m_no_add_chg = false;
  std::uint32_t m_seen_diag_gen = 0;
  bool m_diag_pending = false;

  std::array<std::uint8_t, kMaxIoLen> m_rx_outputs{};
  std::array<std::uint8_t, kMaxIoLen> m_inputs{};
  std::array<std::uint8_t, kMaxIoLen> m_last_rx{};
  std::array<std::uint8_t, kMaxIoLen> m_frozen{};
  std::array<std::uint8_t, kMaxRecordData> m_record_buf{};
  DiagBuilder m_diag;
  std::vector<std::uint16_t> m_scratch_ids;

  PendingRecord m_c1;
  std::vector<C2Connection> m_c2;
  std::uint32_t m_next_record_id = 1;
  SlaveStats m_stats;
  // Mutations only (test-only; see SlaveConfig::mutation).
  std::array<std::uint8_t, kMaxIoLen> m_tear_prev{};  ///< TearConsistent: the previous image
  bus::Ticks m_last_dx = 0;                          ///< SlowSlaveInterval: last answered one
  bool m_last_dx_valid = false;

};

}  // namespace pbvbus::dp
