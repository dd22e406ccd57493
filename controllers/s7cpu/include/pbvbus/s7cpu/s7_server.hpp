#pragma once
// The S7 server of a CPU model, sans-I/O (docs/s7cpu.md): one S7 PDU in (the user data of a
// COTP DT, as stacks/s7 decodes it), the answer PDU out. One S7Server is one server session
// (one connection); several sessions may share one CpuMemory (all on the owner's thread,
// cpu_memory.hpp).
//
// Served: Setup Communication, Read Var and Write Var (protocol-facts.md §H.4; item return codes
// as in stacks/s7 s7_item.hpp), Read SZL (s7_szl.hpp): the owner's SzlSource first
// (szl_source.hpp), then the standard lists 0011/0111, 001C/011C, 0424 (szl_lists.hpp).
// Decisions where the sources are silent are listed in docs/s7cpu.md "Choices".
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/s7/error.hpp"
#include "pbvbus/s7/s7_setup.hpp"
#include "pbvbus/s7cpu/cpu_memory.hpp"

namespace pbvbus::s7cpu {
class SzlSource;
}

namespace pbvbus::s7cpu {

/// Operating mode as SZL W#16#0424 reports it (the low nibble of its "bzu-id" octet; the values
/// snap7's client compares with: S7CpuStatusRun 08, S7CpuStatusStop 04).
namespace cpu_state {
inline constexpr std::uint8_t kUnknown = 0x00;
inline constexpr std::uint8_t kStop = 0x04;
inline constexpr std::uint8_t kRun = 0x08;
/// The H CPUs' modes (SZL xy71 bz_cpu, the same codes as "bzu_id" of W#16#xy24).
inline constexpr std::uint8_t kRunRedundant = 0x09;
}  // namespace cpu_state

/// What the owner tells the server about itself; read at every request, so the owner may change
/// it (e.g. RUN -> STOP) between two calls.
struct CpuInfo {
  std::string order_number = "6ES7 315-2AG10-0AB0";  ///< MLFB, up to 20 characters
  std::uint8_t state = cpu_state::kRun;
  std::uint16_t module_version = 0;  ///< SZL 0011 Ausbg1 of the record W#16#0001
  // SZL 001C (szl_lists.hpp); longer strings are cut at the field's length.
  std::string plc_name = "SIMATIC 300";           ///< index 0001, 24 characters
  std::string module_name = "CPU 315-2 DP";       ///< index 0002, 24
  std::string plant_id;                           ///< index 0003, 32
  std::string serial_number = "S C-PBVBUS000001";  ///< index 0005, 24
  std::string module_type_name = "CPU 315-2 DP";  ///< index 0007, 32
};

/// Header error (error class, error code) of the Ack a refused Job gets: snap7's
/// Code7FunNotAvailable, 0x8104 (class 81, application relationship).
inline constexpr std::uint8_t kRefusedErrorClass = 0x81;
inline constexpr std::uint8_t kRefusedErrorCode = 0x04;
/// Item return code for an item whose data would not fit the negotiated PDU: the octet snap7's
/// server writes (RA_SizeOverPDU: the high octet of Code7DataOverPDU, 0x8500).
inline constexpr std::uint8_t kReturnCodeDataOverPdu = 0x85;

class S7Server {
 public:
  /// `own` = the CPU's limits (AmQ calling/called, PDU length); the default answers the
  /// §3.4 exchange (tools-and-formats.md) with AmQ 1/1 and PDU 240.
  S7Server(CpuMemory& memory, const CpuInfo& info,
           const s7::SetupCommunication& own = {1, 1, 240});

  /// The answer to one S7 PDU. `error` set and `value` empty when there is no answer: the
  /// octets are not an S7 PDU (protocol id, lengths, too short) or are not a Job or Userdata
  /// (decode_s7_pdu's error and offset, or S7WrongPduType); the door then closes the
  /// connection. Every Job and Userdata PDU gets an answer.
  s7::Encoded handle(std::span<const std::uint8_t> pdu);

  bool setup_done() const { return setup_done_; }

  /// Lists beyond the standard ones (szl_source.hpp), asked first; nullptr = none. Not owned.
  void set_szl_source(SzlSource* source) { szl_source_ = source; }
  /// Every Write Var item that succeeds is also written into `mirror` (an H CPU's partner in
  /// redundant mode, controllers/s7h), if the same item addresses the same octets there;
  /// nullptr = none. Not owned. The answer is the primary memory's.
  void set_mirror(CpuMemory* mirror) { mirror_ = mirror; }
  /// The negotiated values (the `own` limits until Setup Communication).
  const s7::SetupCommunication& negotiated() const { return negotiated_; }

 private:
  CpuMemory& memory_;
  const CpuInfo& info_;
  s7::SetupCommunication own_;
  s7::SetupCommunication negotiated_;
  bool setup_done_ = false;
  SzlSource* szl_source_ = nullptr;
  CpuMemory* mirror_ = nullptr;
};

}  // namespace pbvbus::s7cpu
