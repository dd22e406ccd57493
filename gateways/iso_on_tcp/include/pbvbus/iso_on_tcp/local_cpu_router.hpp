#pragma once
// An S7Router for CPUs that answer at once (docs/iso-on-tcp.md "LocalCpuRouter"): each CPU is a
// CpuMemory at a rack/slot; every routed connection gets its own s7cpu::S7Server session on that
// memory (one session per connection, cpu_memory.hpp), and the CPU's connection resources are
// counted.
//
// Decisions (docs/iso-on-tcp.md):
//  - Routing is by the called TSAP's rack and slot only; the connection type octet (PG, OP, S7
//    basic) is not judged, as snap7's server does not.
//  - No CPU at that rack/slot, or a called TSAP that is not 2 octets: DR reason 3 "address
//    unknown". All connection resources of the CPU taken: DR reason 1 "congestion at TSAP".
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "pbvbus/iso_on_tcp/s7_router.hpp"
#include "pbvbus/s7/s7_setup.hpp"
#include "pbvbus/s7cpu/cpu_memory.hpp"
#include "pbvbus/s7cpu/s7_server.hpp"

namespace pbvbus::iso_on_tcp {

/// One CPU behind a LocalCpuRouter. The memory and info are the owner's and must outlive the
/// router and every channel it opened.
struct LocalCpu {
  std::uint8_t rack = 0;
  std::uint8_t slot = 2;
  s7cpu::CpuMemory* memory = nullptr;
  const s7cpu::CpuInfo* info = nullptr;
  s7::SetupCommunication limits{1, 1, 240};  ///< the CPU's AmQ and PDU length
  std::size_t max_connections = 32;          ///< connection resources for S7 clients
};

class LocalCpuRouter final : public S7Router {
 public:
  LocalCpuRouter() = default;
  explicit LocalCpuRouter(const LocalCpu& cpu) { add(cpu); }
  /// A CPU at cpu.rack/cpu.slot; one already there is replaced for new connections.
  void add(const LocalCpu& cpu);

  RouteResult open(const RouteRequest& request) override;

  /// Connections open to the CPU at rack/slot now (0 if there is none).
  std::size_t connections(std::uint8_t rack, std::uint8_t slot) const;

 private:
  struct Entry {
    LocalCpu cpu;
    std::shared_ptr<std::size_t> open = std::make_shared<std::size_t>(0);
  };
  std::vector<Entry> cpus_;
};

}  // namespace pbvbus::iso_on_tcp
