// S7 sessions on controllers/s7cpu's S7Server (s7cpu_sessions.hpp).
#include "pbvbus/mpi_station/s7cpu_sessions.hpp"

#include <algorithm>

namespace pbvbus::mpi_station {

namespace {

class S7CpuSession final : public S7Session {
 public:
  S7CpuSession(s7cpu::CpuMemory& memory, const s7cpu::CpuInfo& info, const s7::SetupCommunication& own)
      : server_(memory, info, own) {}
  std::vector<std::uint8_t> handle(std::span<const std::uint8_t> pdu) override {
    s7::Encoded answer = server_.handle(pdu);
    if (!answer.ok()) return {};  // not an S7 PDU: no answer (docs/s7cpu.md "No answer")
    return std::move(answer.value);
  }

 private:
  s7cpu::S7Server server_;
};

}  // namespace

S7CpuSessionFactory::S7CpuSessionFactory(s7cpu::CpuMemory& memory, const s7cpu::CpuInfo& info,
                                         s7::SetupCommunication own)
    : memory_(memory), info_(info), own_(own) {
  own_.pdu_length = std::min(own_.pdu_length, kMaxMpiPduSize);
}

std::unique_ptr<S7Session> S7CpuSessionFactory::open(std::uint8_t /*peer_address*/) {
  ++opened_;
  return std::make_unique<S7CpuSession>(memory_, info_, own_);
}

}  // namespace pbvbus::mpi_station
