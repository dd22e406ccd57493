#pragma once
// The device side of a DP slave (design.md "Consistent data"; protocol-facts.md §D.5, §E.2,
// §E.5, §F): what a device model or a gateway calls, from any thread, while the SlaveEngine
// runs on the bus thread.
//
// - Process data per module through ProcessImage (seqlock per module, never blocks the bus).
// - Diagnosis: Ext_Diag/Stat_Diag flags, a device-related block, channel diagnoses and module
//   states. Any change makes the next Data_Exchange answer DH ("new diagnosis"), until the
//   owning master has read Slave_Diag.
// - DP-V1 alarms with sequence numbers; they stay in the diagnosis until acknowledged.
// - Record (slot, index) read/write handlers for MSAC_C1 and MSAC_C2. Handlers run on the bus
//   thread inside the request and must be quick; one that needs time returns
//   RecordResult::pending() and later calls complete_read()/complete_write()/complete_error()
//   from any thread; the engine then answers the master's next poll.
//
// Locking: one mutex guards the non-cyclic state (diagnosis, alarms, handlers, completions);
// the Data_Exchange path touches it only through one atomic generation counter.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/dpv1_pdu.hpp"
#include "pbvbus/dp/process_image.hpp"
#include "pbvbus/dp/slave_config.hpp"

namespace pbvbus::dp {

/// DP slave states (protocol-facts.md §D.8).
enum class SlaveState : std::uint8_t { PowerOn, WaitPrm, WaitCfg, DataExch };
std::string_view to_string(SlaveState s);

/// Outcome of a record handler.
struct RecordResult {
  enum class Kind : std::uint8_t { Ok, Error, Pending };
  Kind kind = Kind::Ok;
  std::size_t length = 0;  ///< Read: octets written into the handler's buffer
  Dpv1Error error;
  static RecordResult ok(std::size_t n = 0) { return {Kind::Ok, n, {}}; }
  static RecordResult fail(std::uint8_t code_1, std::uint8_t code_2 = 0) {
    return {Kind::Error, 0, {kErrorDecodeDpv1, code_1, code_2}};
  }
  static RecordResult pending() { return {Kind::Pending, 0, {}}; }
};

/// Who asks, for a record handler.
struct RecordCall {
  std::uint32_t id = 0;  ///< for complete_*() when the handler answers later
  std::uint8_t slot = 0;
  std::uint8_t index = 0;
  std::uint8_t master = 0;  ///< FDL address of the requesting master
  bool c2 = false;          ///< MSAC_C2 connection (else MSAC_C1)
};
/// `out` has room for the requested length; return ok(n) with the octets written.
using RecordReadHandler = std::function<RecordResult(const RecordCall&, std::span<std::uint8_t> out)>;
using RecordWriteHandler =
    std::function<RecordResult(const RecordCall&, std::span<const std::uint8_t> data)>;

enum class AlarmResult : std::uint8_t {
  Ok,
  Closed,            ///< not in Data_Exch with DP-V1 enabled (AL_STATE_CLOSED)
  TypeNotEnabled,    ///< the master did not enable this alarm type (ALARMTYPE_NOTSUPP)
  LimitExpired,      ///< Alarm_Mode limit of outstanding alarms reached (LIMIT_EXPIRED)
  BadArgument,       ///< type 0/7..31/127, or more than 59 octets of data
};

class SlaveEngine;

class SlaveApplication {
 public:
  explicit SlaveApplication(const SlaveLayout& layout);
  SlaveApplication(const SlaveApplication&) = delete;
  SlaveApplication& operator=(const SlaveApplication&) = delete;

  // --- Process data (any thread) ---
  std::size_t modules() const { return m_image.modules(); }
  const ModuleLayout& module(std::size_t m) const { return m_image.module(m); }
  /// Replaces a module's inputs as one unit; false if the module or the length is wrong.
  bool write_inputs(std::size_t module, std::span<const std::uint8_t> data);
  /// Copies a module's outputs as one unit; false if the module or the length is wrong.
  bool read_outputs(std::size_t module, std::span<std::uint8_t> out) const;
  /// Changes whenever the bus hands new outputs to a module (for change detection).
  std::uint32_t outputs_generation(std::size_t module) const;
  ProcessImage& image() { return m_image; }

  // --- State as seen by the bus (any thread) ---
  SlaveState state() const { return m_state.load(std::memory_order_acquire); }
  std::uint8_t master_address() const { return m_master.load(std::memory_order_acquire); }
  /// True while outputs are held in the safe state (not in Data_Exch, Clear_Data, fail-safe).
  bool outputs_safe() const { return m_outputs_safe.load(std::memory_order_acquire); }

  // --- Diagnosis (any thread) ---
  void set_ext_diag(bool on);
  void set_stat_diag(bool on);
  /// Content of the device-related block (without its header); empty = no block.
  void set_device_diag(std::span<const std::uint8_t> data);
  void add_channel_diag(const ChannelDiag& c);
  void remove_channel_diag(const ChannelDiag& c);
  void clear_channel_diags();
  /// A module state other than Ok sets its bit in the identifier-related block and, with
  /// DP-V1 enabled, shows up in the Module_Status block.
  void set_module_state(std::size_t module, ModuleState s);

  /// A DP-V1 status PDU (Status_Message 0x81, Prm_Cmd_Ack 0x9E, Red_State 0x9F, 0xA0..0xFE
  /// manufacturer-specific) kept in every diagnosis until cleared, whatever the DP-V1 mode (a
  /// redundancy layer shows Red_State before parameterisation). One per (type, slot): setting it
  /// again replaces it. False for a type without bit 7, Module_Status (the engine builds that
  /// from set_module_state()), or more than 59 octets.
  bool set_status(std::uint8_t status_type, std::uint8_t slot, std::uint8_t specifier,
                  std::span<const std::uint8_t> data = {});
  void clear_status(std::uint8_t status_type, std::uint8_t slot);
  /// Makes the owner's next Data_Exchange replies high priority (DH) until it reads Slave_Diag,
  /// without changing the diagnosis (e.g. a redundancy state change the master must fetch).
  void request_diag_read() { diag_changed(); }

  // --- DP-V1 alarms (any thread) ---
  /// Queues an alarm; its Seq_Nr is returned in *seq_nr.
  AlarmResult raise_alarm(std::uint8_t type, std::uint8_t slot, AlarmSpec spec, bool add_ack,
                          std::span<const std::uint8_t> data = {}, std::uint8_t* seq_nr = nullptr);
  /// Alarms not yet acknowledged by the master.
  std::size_t alarms_outstanding() const;
  /// Called (on the bus thread) when the master acknowledges an alarm.
  void on_alarm_ack(std::function<void(std::uint8_t type, std::uint8_t slot, std::uint8_t seq)> cb);

  // --- Records (any thread) ---
  void on_read(std::uint8_t slot, std::uint8_t index, RecordReadHandler h);
  void on_write(std::uint8_t slot, std::uint8_t index, RecordWriteHandler h);
  /// The handler for a Write to a (slot, index) without a handler of its own (e.g. a module's
  /// parameter records at any index; devices/slaves module_records.hpp). Unset: such a Write is
  /// answered "invalid index" / "invalid slot" as before.
  void on_write_any(RecordWriteHandler h);
  void complete_read(std::uint32_t id, std::span<const std::uint8_t> data);
  void complete_write(std::uint32_t id);
  void complete_error(std::uint32_t id, Dpv1Error e);

 private:
  friend class SlaveEngine;

  struct Alarm {
    std::uint8_t type = 0;
    std::uint8_t slot = 0;
    std::uint8_t specifier = 0;
    std::uint8_t len = 0;
    std::array<std::uint8_t, 59> data{};
  };
  struct Completion {
    bool error = false;
    Dpv1Error err;
    std::vector<std::uint8_t> data;
  };
  void diag_changed() { m_diag_gen.fetch_add(1, std::memory_order_acq_rel); }

  ProcessImage m_image;
  std::atomic<SlaveState> m_state{SlaveState::WaitPrm};
  std::atomic<std::uint8_t> m_master{0xFF};
  std::atomic<bool> m_outputs_safe{true};
  std::atomic<std::uint32_t> m_diag_gen{0};

  mutable std::mutex m_mu;
  // Guarded by m_mu:
  bool m_ext_diag = false;
  bool m_stat_diag = false;
  std::vector<std::uint8_t> m_device_diag;
  std::vector<ChannelDiag> m_channels;
  std::vector<ModuleState> m_module_states;
  std::vector<Alarm> m_alarms;            ///< outstanding, oldest first
  std::vector<Alarm> m_status;            ///< status PDUs (same layout as an alarm)
  bool m_alarms_open = false;             ///< Data_Exch with DPV1_Enable
  std::uint8_t m_alarm_enables = 0;       ///< DPV1_Status_2 enable bits accepted at Set_Prm
  std::uint8_t m_alarm_mode = 0;
  std::uint8_t m_next_seq = 0;
  std::function<void(std::uint8_t, std::uint8_t, std::uint8_t)> m_alarm_ack_cb;
  std::map<std::uint16_t, RecordReadHandler> m_read_handlers;
  std::map<std::uint16_t, RecordWriteHandler> m_write_handlers;
  RecordWriteHandler m_write_any;
  std::map<std::uint32_t, Completion> m_completions;
};

}  // namespace pbvbus::dp
