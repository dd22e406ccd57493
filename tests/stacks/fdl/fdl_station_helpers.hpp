#pragma once
// Test helpers for the FDL station tests: a scripted device that sends given bytes at given
// times (a stand-in for a master or a slave whose frames are written by hand in the test).

#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/fdl/station.hpp"

namespace pbvbus::fdl::test {

using Bytes = std::vector<std::uint8_t>;

/// Sends what the test tells it to, when told; records what it hears.
class ScriptDevice final : public bus::Device {
 public:
  void on_power_on(bus::Ticks) override {}
  struct Heard {
    Bytes bytes;
    bus::Ticks start = 0;
    bus::Ticks end = 0;
    bus::Ticks idle_before = 0;
    std::uint16_t flags = 0;
  };
  void on_frame(const bus::RxFrame& f) override {
    heard.push_back({Bytes(f.bytes.begin(), f.bytes.end()), f.start, f.end, f.idle_before, f.flags});
  }
  void on_timer(bus::Ticks) override {}
  void send(bus::Ticks at, const Bytes& bytes) { port().transmit(at, bytes); }
  std::vector<Heard> heard;
};

/// A slave user answering every SRD with `reply` as DL data (SDA with SC).
class DataSlaveUser final : public ResponderUser {
 public:
  explicit DataSlaveUser(Bytes r = {}) : reply(std::move(r)) {}
  void on_request(const Indication& ind, Reply& r) override {
    ++requests;
    if (ind.fn == RequestFn::SdaHigh || ind.fn == RequestFn::SdaLow)
      r.short_ack();
    else if (reply.empty())
      r.short_ack();
    else
      r.respond(ResponseStatus::DL, reply);
  }
  Bytes reply;
  int requests = 0;
};

/// A master user that offers, per token visit, `high_per_visit` high-priority and
/// `low_per_visit` low-priority requests (negative: unlimited), copies of `high` / `low`.
class QueueMasterUser final : public InitiatorUser {
 public:
  bool next_request(Priority prio, bus::Ticks, Request& out) override {
    int& left = prio == Priority::High ? m_high_left : m_low_left;
    if (left == 0) return false;
    if (left > 0) --left;
    const Request& src = prio == Priority::High ? high : low;
    out.da = src.da;
    out.fn = src.fn;
    out.dsap = src.dsap;
    out.ssap = src.ssap;
    out.data.assign(src.data.begin(), src.data.end());
    out.tag = ++m_tag;
    return true;
  }
  void on_confirmation(const Confirmation& c) override {
    confirmations.push_back({c.now, c.tag, c.da, c.result, c.short_ack, c.status, c.responder_type,
                             Bytes(c.data.begin(), c.data.end()), c.retries});
  }
  void on_token(bus::Ticks now, bus::Ticks trr) override {
    tokens.push_back({now, trr});
    m_high_left = high_per_visit;
    m_low_left = low_per_visit;
  }
  struct Con {
    bus::Ticks now;
    std::uint64_t tag;
    std::uint8_t da;
    Confirmation::Result result;
    bool short_ack;
    ResponseStatus status;
    StationType type;
    Bytes data;
    std::uint32_t retries;
  };
  int high_per_visit = 0;
  int low_per_visit = 0;
  Request high, low;
  std::vector<Con> confirmations;
  std::vector<std::pair<bus::Ticks, bus::Ticks>> tokens;

 private:
  int m_high_left = 0;
  int m_low_left = 0;
  std::uint64_t m_tag = 0;
};

}  // namespace pbvbus::fdl::test
