#include "pbvbus/iso_on_tcp/local_cpu_router.hpp"

#include <algorithm>
#include <string>

#include "pbvbus/s7/cotp_disconnect.hpp"

namespace pbvbus::iso_on_tcp {

namespace {

/// One S7Server session; answers synchronously, never closes on its own.
class LocalChannel final : public S7Channel {
 public:
  LocalChannel(const LocalCpu& cpu, std::shared_ptr<std::size_t> open)
      : server_(*cpu.memory, *cpu.info, cpu.limits), open_(std::move(open)) {
    ++*open_;
  }
  ~LocalChannel() override { --*open_; }

  void request(std::vector<std::uint8_t> pdu, Reply reply) override {
    s7::Encoded answer = server_.handle(pdu);
    reply(answer.ok() ? std::move(answer.value) : std::vector<std::uint8_t>{});
  }
  void on_closed(Closed) override {}  // a local CPU's connection does not break

 private:
  s7cpu::S7Server server_;
  std::shared_ptr<std::size_t> open_;
};

std::string where(std::uint8_t rack, std::uint8_t slot) {
  return "rack " + std::to_string(rack) + " slot " + std::to_string(slot);
}

}  // namespace

void LocalCpuRouter::add(const LocalCpu& cpu) {
  for (auto& e : cpus_) {
    if (e.cpu.rack == cpu.rack && e.cpu.slot == cpu.slot) {
      e.cpu = cpu;
      return;
    }
  }
  cpus_.push_back(Entry{cpu});
}

RouteResult LocalCpuRouter::open(const RouteRequest& request) {
  if (!request.called)
    return RouteResult::refuse(s7::dr_reason::kAddressUnknown,
                               "called TSAP of " + std::to_string(request.called_tsap.size()) +
                                   " octets is no rack/slot TSAP");
  const auto& t = *request.called;
  for (auto& e : cpus_) {
    if (e.cpu.rack != t.rack || e.cpu.slot != t.slot) continue;
    if (*e.open >= e.cpu.max_connections)
      return RouteResult::refuse(s7::dr_reason::kCongestionAtTsap,
                                 "all " + std::to_string(e.cpu.max_connections) +
                                     " connection resources of the CPU at " +
                                     where(t.rack, t.slot) + " in use");
    RouteResult r;
    r.channel = std::make_unique<LocalChannel>(e.cpu, e.open);
    return r;
  }
  return RouteResult::refuse(s7::dr_reason::kAddressUnknown, "no CPU at " + where(t.rack, t.slot));
}

std::size_t LocalCpuRouter::connections(std::uint8_t rack, std::uint8_t slot) const {
  for (const auto& e : cpus_)
    if (e.cpu.rack == rack && e.cpu.slot == slot) return *e.open;
  return 0;
}

}  // namespace pbvbus::iso_on_tcp
