// TestBus: the tester's line (test_bus.hpp). The tester is a plain bus::Device attached first on
// the cable; every "send and wait" is a run of the scheduler (fast) or of the PacedRunner in
// small slices (paced) until the reply has been delivered or the slot time has passed.
//
// Decisions:
// - The reply is the first frame heard whose START lies in [request end, request end + TSL]
//   (the slot time counts to the reply's start, as a master's does). A reply that starts in time
//   is awaited to its end, however long (carrier sense: DevicePort::receiving()). Everything else
//   the tester hears (a frame that started before the request ended, one after the window,
//   frames during idle()) goes to extra_frames(), as do line events (power, cuts).
// - "Line free" = the end of the last frame on the line, whoever sent it (own transmissions
//   included); a request starts TSYN bit times after it at the earliest. A frame that is still
//   arriving when a request is due is awaited first.
// - Paced: slices of about 1 ms of wall time (at least one bit time of virtual time); a wait may
//   take the wall time its virtual span needs at the runner's speed plus paced_wait_limit, then
//   it ends (as "no reply" for a request), never as a hang.

#include <algorithm>
#include <chrono>

#include "pbvbus/bus/tap.hpp"
#include "pbvbus/conformance/test_bus.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::conformance {

namespace {

/// SA of an encoded request (extension bit removed); 0 if the frame is too short to tell.
std::uint8_t source_of(std::span<const std::uint8_t> t) {
  if (t.empty()) return 0;
  std::size_t at = 0;
  switch (t[0]) {
    case fdl::kSD1:
    case fdl::kSD3:
    case fdl::kSD4: at = 2; break;
    case fdl::kSD2: at = 5; break;
    default: return 0;
  }
  return at < t.size() ? static_cast<std::uint8_t>(t[at] & 0x7F) : 0;
}

}  // namespace

class TestBus::Tester final : public bus::Device {
 public:
  struct Heard {
    std::vector<std::uint8_t> bytes;
    bus::Ticks start = 0;
    bus::Ticks end = 0;
    std::uint16_t flags = 0;
  };

  /// Line events (faults and repairs) go to the owner's extra frames as they happen.
  class EventTap final : public bus::Tap {
   public:
    explicit EventTap(TestBus& owner) : m_owner(owner) {}
    void on_frame(const bus::TapFrame&) override {}
    void on_line_event(const bus::LineEvent& e) override {
      ExtraFrame x;
      x.start = x.end = e.time;
      x.event = std::string(bus::to_string(e.kind));
      if (e.a >= 0 && e.a < m_owner.line().attachment_count()) x.event += " " + m_owner.line().label(e.a);
      if (e.b >= 0 && e.b < m_owner.line().attachment_count()) x.event += "/" + m_owner.line().label(e.b);
      m_owner.m_extra.push_back(std::move(x));
    }

   private:
    TestBus& m_owner;
  };

  explicit Tester(TestBus& owner) : tap(owner) {}

  void on_power_on(bus::Ticks) override {}
  void on_frame(const bus::RxFrame& f) override {
    heard.push_back({std::vector<std::uint8_t>(f.bytes.begin(), f.bytes.end()), f.start, f.end, f.flags});
    last_end = std::max(last_end, f.end);
  }
  void on_timer(bus::Ticks) override {}
  const char* kind() const override { return "tester"; }

  bool receiving() const { return bound() && port().receiving(); }
  /// Puts `bytes` on the line at `start`; returns the end of its last stop bit.
  bus::Ticks send(bus::Ticks start, std::span<const std::uint8_t> bytes) {
    port().transmit(start, bytes);
    const bus::Ticks end = start + bus::chars_to_ticks(static_cast<std::int64_t>(bytes.size()), port().baud());
    last_end = std::max(last_end, end);
    return end;
  }

  std::vector<Heard> heard;
  bus::Ticks last_end = 0;  // end of the last frame on the line (heard or sent)
  EventTap tap;
};

TestBus::TestBus(TestBusOptions options) : m_opt(std::move(options)) {
  if (m_opt.paced) m_runner = std::make_unique<bus::PacedRunner>(m_sched, *m_opt.paced);
  m_line = std::make_unique<bus::Line>(m_sched, "tester", m_opt.params.baud, m_opt.seed);
  m_tester = std::make_unique<Tester>(*this);
  m_tester_att = m_line->attach(*m_tester, "tester " + std::to_string(m_opt.tester_address));
}

TestBus::~TestBus() {
  // The line refers to the tester (device and tap): it goes first.
  if (m_line) m_line->remove_tap(m_tester->tap);
  m_line.reset();
  m_tester.reset();
}

bus::AttachmentId TestBus::attach_dut(bus::Device& dut, std::string label) {
  m_dut_att = m_line->attach(dut, std::move(label));
  m_dut_attached = true;
  return m_dut_att;
}

void TestBus::start() {
  m_line->start();
  // Events from here on: the initial power-on of every attachment is no finding.
  m_line->add_tap(m_tester->tap);
}

bus::Ticks TestBus::now() const { return m_sched.now(); }

bus::Ticks TestBus::line_free_at() const { return m_tester->last_end; }

std::span<const Exchange> TestBus::since(std::size_t mark) const {
  const std::size_t from = std::min(mark, m_transcript.size());
  return std::span<const Exchange>(m_transcript).subspan(from);
}

void TestBus::run_until(bus::Ticks t, const std::function<bool()>& done) {
  auto finished = [&] { return done && done(); };
  if (!m_runner) {
    while (!finished()) {
      if (m_sched.next_time() > t) {
        if (m_sched.now() < t) m_sched.run_until(t);
        return;
      }
      m_sched.step();
    }
    return;
  }
  // Paced: slices of ~1 ms wall time, bounded by paced_wait_limit.
  const bus::Speed sp = m_runner->speed();
  const bus::Ticks slice = std::max<bus::Ticks>(
      bus::ticks_per_bit(baud()), bus::kTicksPerMs * static_cast<bus::Ticks>(sp.num) /
                                      static_cast<bus::Ticks>(std::max<std::uint32_t>(sp.den, 1)));
  // The wall bound is slack beyond the wall time the virtual wait takes at this speed: a long
  // virtual wait (idle, watchdog) runs to its end; a runner that stalls gives up.
  const bus::Ticks span = std::max<bus::Ticks>(0, t - m_sched.now());
  const auto wall_of_span = std::chrono::nanoseconds(
      bus::ticks_to_ns(span) / std::max<std::uint32_t>(sp.num, 1) * static_cast<std::int64_t>(sp.den));
  const auto wall_end = std::chrono::steady_clock::now() + wall_of_span + m_opt.paced_wait_limit;
  while (!finished() && m_sched.now() < t) {
    if (std::chrono::steady_clock::now() >= wall_end) return;
    m_runner->run_until(std::min(t, m_sched.now() + slice));
  }
}

void TestBus::drain_heard() {
  for (auto& h : m_tester->heard)
    m_extra.push_back({std::move(h.bytes), h.start, h.end, h.flags, {}});
  m_tester->heard.clear();
}

void TestBus::settle() {
  // A frame still arriving (a late reply, another station's frame): wait for its end first, so
  // the next request keeps TSYN after it. Bounded by the longest frame.
  if (m_tester->receiving()) {
    const bus::Ticks bound = now() + bus::chars_to_ticks(static_cast<std::int64_t>(fdl::kMaxFrame) + 1, baud());
    run_until(bound, [this] { return !m_tester->receiving(); });
  }
  drain_heard();
}

Exchange TestBus::transmit(std::span<const std::uint8_t> telegram, std::string note,
                           std::optional<bus::Ticks> not_before, bool expects_reply) {
  settle();
  Exchange e;
  e.request.assign(telegram.begin(), telegram.end());
  e.expects_reply = expects_reply;
  e.sender = source_of(telegram);
  e.note = std::move(note);
  e.baud = baud();
  if (telegram.empty()) {
    // Nothing to send (a request the codec refused): recorded, never answered.
    e.request_start = e.request_end = now();
    m_transcript.push_back(e);
    return e;
  }

  bus::Ticks start = std::max(now(), m_tester->last_end + ticks(fdl::BusParams::kTsyn));
  if (not_before) start = std::max(start, *not_before);
  e.request_start = start;
  e.request_end = m_tester->send(start, telegram);

  const bus::Ticks end = e.request_end;
  if (!expects_reply) {
    run_until(end + ticks(fdl::BusParams::kTsyn), {});
    drain_heard();
    m_transcript.push_back(e);
    return e;
  }

  const bus::Ticks deadline = end + ticks(static_cast<std::int64_t>(m_opt.params.tsl));
  auto reply_index = [&]() -> std::optional<std::size_t> {
    for (std::size_t i = 0; i < m_tester->heard.size(); ++i) {
      const auto& h = m_tester->heard[i];
      if (h.start >= end && h.start <= deadline) return i;
    }
    return std::nullopt;
  };
  run_until(deadline, [&] { return reply_index().has_value(); });
  if (!reply_index() && m_tester->receiving() && now() >= deadline) {
    // Started within the slot time (we are at its end and a frame is on the line): await it.
    const bus::Ticks bound = now() + bus::chars_to_ticks(static_cast<std::int64_t>(fdl::kMaxFrame) + 1, baud());
    run_until(bound, [&] { return reply_index().has_value() || !m_tester->receiving(); });
  }
  if (auto i = reply_index()) {
    auto& h = m_tester->heard[*i];
    e.answered = true;
    e.response = std::move(h.bytes);
    e.response_flags = h.flags;
    e.response_start = h.start;
    e.response_end = h.end;
    e.tsdr_bits = bits(h.start - end);
    m_tester->heard.erase(m_tester->heard.begin() + static_cast<std::ptrdiff_t>(*i));
  }
  drain_heard();
  m_transcript.push_back(e);
  return e;
}

Exchange TestBus::request(std::span<const std::uint8_t> telegram, std::string note,
                          std::optional<bus::Ticks> not_before) {
  return transmit(telegram, std::move(note), not_before, true);
}

Exchange TestBus::send_no_reply(std::span<const std::uint8_t> telegram, std::string note) {
  return transmit(telegram, std::move(note), std::nullopt, false);
}

void TestBus::idle(bus::Ticks duration) {
  settle();
  run_until(now() + duration, {});
  drain_heard();
}

void TestBus::set_dut_power(bool on) {
  if (m_dut_attached) m_line->set_power(m_dut_att, on);
}

void TestBus::set_bus_interrupted(bool cut) {
  if (m_dut_attached) m_line->set_cut_between(m_tester_att, m_dut_att, cut);
}

}  // namespace pbvbus::conformance
