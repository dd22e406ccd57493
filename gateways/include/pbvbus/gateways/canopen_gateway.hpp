#pragma once
// The CANopen-style CAN gateway (docs/gateway-canopen.md; CiA 301 predefined connection set,
// tools-and-formats.md §2.6; docs/gateway-canopen.md): every DP slave of one master system is a
// CANopen node on a virtual CAN segment (a CanHub). Sans-I/O: the gateway is one hub port and
// one scheduler target in virtual time; the transports (SLCAN, socketcand, SocketCAN) are other
// ports on the same hub and belong to the doors.
//
// Per node (node id = the slave's PROFIBUS address unless remapped):
// - TPDO1..4 (0x180/0x280/0x380/0x480 + node): input octets 0..7, 8..15, 16..23, 24..31 of one
//   DP cycle's input telegram, DLC = the octets present. Sent when its octets changed (compared
//   every change-detection period) and every TPDO cycle time — only while the slave is in data
//   exchange with valid data, so stale data is never sent; the EMCY / heartbeat say why.
// - RPDO1..4 (0x200/0x300/0x400/0x500 + node) → output octets 0..7, ...: read-modify-write of
//   the output telegram, every module the frame touches rewritten whole, all in the frame's
//   handler (one DP cycle).
// - Heartbeat 0x700 + node every producer heartbeat time (object 0x1017), boot-up (0x00) when
//   the slave reaches data exchange (first time and each return) and after NMT reset.
// - EMCY 0x080 + node: 0x8130 on a station failure, 0xFF00 on Ext_Diag / changed extended
//   diagnosis, 0x0000 when a condition clears.
// - NMT (0x000): start/stop/pre-operational → Operate/Stop/Clear of the MASTER: a DP master has
//   one mode for all its slaves, so an NMT command to any of our nodes (or to all) changes the
//   mode of the whole master system. Reset node / communication → boot-up + heartbeat restart.
// - SDO server (0x600 + node → 0x580 + node): expedited upload of the dictionary in
//   canopen_objects.hpp, expedited download of 0x1017 only.
//
// Timing decisions: one scheduler event at the earliest due time (change detection, TPDO cycle,
// each node's heartbeat). With start(t0): change detection at t0 + k·period (k ≥ 0, so the
// first images go out at t0 as "changed"), cyclic TPDOs at t0 + k·cycle (k ≥ 1), heartbeats at
// t0 + k·heartbeat (k ≥ 1) — after an NMT reset or a 0x1017 write at t: t + k·heartbeat. At one
// instant the order is: per node (ascending address) EMCY/boot-up, then its TPDOs; then the
// heartbeats. A cyclic TPDO and a changed one due at the same instant are one frame.
//
// Threading: the bus thread only (hub receivers and scheduler events), like every door.
// Lifetime: the scheduler has no cancel, so the gateway must be destroyed only when its
// scheduler will not run again (as every other target); the destructor removes its hub port.
// Frames that arrive before start() are ignored (the node is not on the bus yet).

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"
#include "pbvbus/gateways/can_frame.hpp"
#include "pbvbus/gateways/canopen_objects.hpp"
#include "pbvbus/gateways/process_source.hpp"

namespace pbvbus::gateways {

struct CanopenOptions {
  /// Cyclic TPDO period ("every cycle time"); 0 = on change only.
  bus::Ticks tpdo_cycle = 100 * bus::kTicksPerMs;
  /// How often inputs and states are compared; a changed TPDO goes out at the next such tick.
  /// Must be > 0 (a non-positive value is replaced by 1 ms with a warning).
  bus::Ticks change_period = 1 * bus::kTicksPerMs;
  /// Producer heartbeat time in ms (object 0x1017's initial value); 0 = no heartbeat.
  std::uint16_t heartbeat_ms = 1000;
  /// PROFIBUS address → node id (1..127); addresses not listed use node id = address.
  std::map<std::uint8_t, std::uint8_t> node_ids;
  /// False: NMT commands are refused (counted), the master's mode is not touched.
  bool accept_nmt = true;
};

/// One node of the gateway: which slave, which PDOs.
struct CanopenNode {
  std::uint8_t address = 0;
  std::uint8_t node = 0;
  std::string name;
  std::size_t input_len = 0;
  std::size_t output_len = 0;
  std::size_t tpdos = 0;        ///< TPDOs that carry octets (0..4)
  std::size_t rpdos = 0;        ///< RPDOs that map octets (0..4)
  bool outputs_writable = true;
};

/// The node and PDO map of a master system under given options, with the warnings (inputs or
/// outputs beyond 32 octets, addresses without a node id, bad or duplicate node ids).
struct CanopenMap {
  std::vector<CanopenNode> nodes;  ///< ascending by address
  std::vector<std::string> warnings;
};
CanopenMap build_canopen_map(std::span<const SourceSlave> slaves, const CanopenOptions& options);
/// A table for people: one line per PDO with its COB-ID and octet range, then the warnings.
std::string to_text(const CanopenMap& map);

struct CanopenStats {
  // Sent, by kind.
  std::uint64_t tpdo_sent = 0;
  std::uint64_t heartbeat_sent = 0;
  std::uint64_t bootup_sent = 0;
  std::uint64_t emcy_sent = 0;
  std::uint64_t sdo_sent = 0;        ///< responses, aborts included
  // Received, by kind (a frame is counted once).
  std::uint64_t rpdo_received = 0;   ///< RPDOs applied to the outputs
  std::uint64_t nmt_received = 0;    ///< NMT commands carried out
  std::uint64_t sdo_received = 0;    ///< SDO requests for our nodes (answered or client aborts)
  std::uint64_t ignored = 0;         ///< not for us: other COB-IDs, foreign nodes, RTR, extended
  std::uint64_t bad = 0;             ///< for us but malformed (NMT DLC != 2, unknown NMT cs)
  // Detail.
  std::uint64_t rpdo_refused = 0;    ///< RPDOs not applied: outputs not writable / nothing mapped
  std::uint64_t nmt_refused = 0;     ///< NMT not accepted by options or by the master system
  std::uint64_t sdo_aborts = 0;      ///< abort responses sent
};

class CanopenGateway final : public bus::EventTarget {
 public:
  CanopenGateway(bus::Scheduler& sched, ProcessSource& source, CanHub& hub,
                 CanopenOptions options = {});
  ~CanopenGateway();
  CanopenGateway(const CanopenGateway&) = delete;
  CanopenGateway& operator=(const CanopenGateway&) = delete;

  /// Begins: the first change-detection tick runs at `now`. A second call does nothing.
  void start(bus::Ticks now);

  const CanopenStats& stats() const { return m_stats; }
  const std::vector<std::string>& warnings() const { return m_map.warnings; }
  const CanopenMap& map() const { return m_map; }
  CanHub::PortId port() const { return m_port; }
  /// Current error register (0x1001) of a node; 0 for an unknown node.
  std::uint8_t error_register(std::uint8_t node) const;
  /// Current producer heartbeat time (0x1017) of a node in ms; 0 for an unknown node.
  std::uint16_t heartbeat_ms(std::uint8_t node) const;

  void on_event(bus::Ticks now, std::uint64_t tag) override;

 private:
  struct Node {
    CanopenNode map;
    const SourceSlave* slave = nullptr;
    std::uint16_t heartbeat_ms = 0;
    bus::Ticks next_heartbeat = bus::kNever;
    // State seen at the last change-detection tick.
    bool seen = false;            ///< at least one tick done
    bool data_exchange = false;
    std::uint64_t failures = 0;
    bool failure_active = false;  ///< EMCY 0x8130 sent, data exchange not back yet
    bool ext_active = false;      ///< EMCY 0xFF00 sent, Ext_Diag not cleared yet
    std::vector<std::uint8_t> ext_diag;  ///< extended diagnosis octets (Slave_Diag from octet 7)
    // Octets of each TPDO as last sent; `sent[i]` false: send at the next tick whatever it is.
    std::array<std::array<std::uint8_t, 8>, 4> last{};
    std::array<std::uint8_t, 4> last_len{};
    std::array<bool, 4> sent{};
  };

  void on_frame(const CanFrame& f, bus::Ticks now);
  void on_nmt(const CanFrame& f, bus::Ticks now);
  void on_rpdo(Node& n, std::size_t pdo, const CanFrame& f);
  void on_sdo(Node& n, const CanFrame& f, bus::Ticks now);

  void check_node(Node& n, bus::Ticks now, bool cyclic);
  void send_tpdos(Node& n, bus::Ticks now, bool cyclic);
  void send_emcy(const Node& n, std::uint16_t code, std::uint8_t reg,
                 std::array<std::uint8_t, 5> manufacturer, bus::Ticks now);
  void send_bootup(Node& n, bus::Ticks now);
  void send(std::uint32_t id, std::span<const std::uint8_t> data, bus::Ticks now);
  void restart_heartbeat(Node& n, bus::Ticks now);
  std::uint8_t error_register(const Node& n) const;
  SlaveStatus status_of(const Node& n) const;
  Node* node_by_id(std::uint8_t node);
  const Node* node_by_id(std::uint8_t node) const;
  void arm();

  bus::Scheduler& m_sched;
  ProcessSource& m_source;
  CanHub& m_hub;
  CanopenOptions m_opt;
  CanopenMap m_map;
  std::vector<Node> m_nodes;
  std::array<std::int16_t, 128> m_by_node{};  ///< node id → index in m_nodes, -1 none
  CanHub::PortId m_port = 0;
  bool m_started = false;
  bus::Ticks m_next_change = bus::kNever;
  bus::Ticks m_next_cycle = bus::kNever;
  bus::Ticks m_armed_at = bus::kNever;
  std::uint64_t m_generation = 0;
  // Reused copies; two of them because a hub receiver may answer a TPDO with an RPDO inside
  // our send (the RPDO handler must not touch the buffer the TPDO loop is reading).
  std::vector<std::uint8_t> m_in_buf;
  std::vector<std::uint8_t> m_out_buf;
  CanopenStats m_stats;
};

}  // namespace pbvbus::gateways
