#pragma once
// S7SessionFactory for controllers/s7cpu's S7Server (docs/s7cpu.md): every MPI connection gets
// its own S7Server (its own negotiated PDU size) on the owner's one CpuMemory.
//
// PDU size over MPI: one data message carries at most mpi::kMaxDataLen = 242 octets of S7 PDU
// (the FDL DU's 246 minus the SAP octets, F1 and the message number, docs/mpi.md). The
// negotiated PDU size must fit, and S7 PDU sizes are offered in steps that CPUs use (240,
// 480, 960), so the CPU side offers at most kMaxMpiPduSize = 240: a larger `own.pdu_length` is
// lowered to 240 here. Setup Communication then gives the client min(its request, 240).

#include <cstdint>
#include <memory>

#include "pbvbus/mpi_station/s7_session.hpp"
#include "pbvbus/s7/s7_setup.hpp"
#include "pbvbus/s7cpu/cpu_memory.hpp"
#include "pbvbus/s7cpu/s7_server.hpp"

namespace pbvbus::mpi_station {

/// The largest S7 PDU size a CPU offers over MPI (see the header comment).
inline constexpr std::uint16_t kMaxMpiPduSize = 240;

class S7CpuSessionFactory final : public S7SessionFactory {
 public:
  /// `memory` and `info` must outlive the factory and every session it opened.
  S7CpuSessionFactory(s7cpu::CpuMemory& memory, const s7cpu::CpuInfo& info,
                      s7::SetupCommunication own = {1, 1, kMaxMpiPduSize});
  std::unique_ptr<S7Session> open(std::uint8_t peer_address) override;
  /// The limits each session offers (PDU size at most kMaxMpiPduSize).
  const s7::SetupCommunication& own() const { return own_; }
  std::uint32_t sessions_opened() const { return opened_; }

 private:
  s7cpu::CpuMemory& memory_;
  const s7cpu::CpuInfo& info_;
  s7::SetupCommunication own_;
  std::uint32_t opened_ = 0;
};

}  // namespace pbvbus::mpi_station
