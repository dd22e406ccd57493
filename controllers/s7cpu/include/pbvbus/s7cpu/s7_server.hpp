#pragma once
// The S7 server of a CPU model, sans-I/O (docs/s7cpu.md): one S7 PDU in (the user data of a
// COTP DT, as stacks/s7 decodes it), the answer PDU out. One S7Server is one server session
// (one connection); several sessions may share one CpuMemory (all on the owner's thread,
// cpu_memory.hpp).
//
// Served: Setup Communication, Read Var and Write Var (protocol-facts.md §H.4; item return codes
// as in stacks/s7 s7_item.hpp), Read SZL W#16#0011 and W#16#0424 (s7_szl.hpp). Decisions where
// the sources are silent are listed in docs/s7cpu.md "Choices".
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/s7/error.hpp"
#include "pbvbus/s7/s7_setup.hpp"
#include "pbvbus/s7cpu/cpu_memory.hpp"

namespace pbvbus::s7cpu {

/// Operating mode as SZL W#16#0424 reports it (the low nibble of its "bzu-id" octet; the values
/// snap7's client compares with: S7CpuStatusRun 08, S7CpuStatusStop 04).
namespace cpu_state {
inline constexpr std::uint8_t kUnknown = 0x00;
inline constexpr std::uint8_t kStop = 0x04;
inline constexpr std::uint8_t kRun = 0x08;
}  // namespace cpu_state

/// What the owner tells the server about itself; read at every request, so the owner may change
/// it (e.g. RUN -> STOP) between two calls.
struct CpuInfo {
  std::string order_number = "6ES7 315-2AG10-0AB0";  ///< MLFB, up to 20 characters
  std::uint8_t state = cpu_state::kRun;
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
  /// The negotiated values (the `own` limits until Setup Communication).
  const s7::SetupCommunication& negotiated() const { return negotiated_; }

 private:
  CpuMemory& memory_;
  const CpuInfo& info_;
  s7::SetupCommunication own_;
  s7::SetupCommunication negotiated_;
  bool setup_done_ = false;
};

}  // namespace pbvbus::s7cpu
