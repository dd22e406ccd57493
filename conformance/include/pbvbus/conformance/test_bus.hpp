#pragma once
// The tester's side of a conformance run (docs/conformance.md): one line with a tester station (an
// initiator that the battery drives step by step) and the device under test. Sans-I/O like the
// rest: the tester is a bus::Device; TestBus turns "send this telegram and wait for the answer"
// into a synchronous call by running the scheduler (fast) or the PacedRunner (an outside DUT
// behind a pty, at a slowed speed) until the reply has arrived or the slot time has passed.
//
// Timing rules of the tester (so that a conformant slave is never blamed for the tester):
// - A request goes out after at least TSYN (33 bit times) of idle line since the end of the last
//   frame anyone sent (the slave's TSYN rule), or later if `not_before` says so.
// - The reply window is TSL bit times from the end of the request's last stop bit to the START
//   of the reply (the slot time of the line's bus parameters); a reply that starts later is an
//   "extra" frame, not the reply.
// - tsdr_bits of an Exchange = idle bit times between the request's end and the reply's start
//   (exact: ticks / ticks_per_bit). The battery judges it against [min TSDR, max TSDR].
//
// Every frame on the line is recorded in order (transcript()), requests with what answered them;
// a test takes its evidence from there (mark() / since()).

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"
#include "pbvbus/fdl/bus_params.hpp"

namespace pbvbus::conformance {

/// One telegram the tester sent and what came back.
struct Exchange {
  std::vector<std::uint8_t> request;  ///< SD..ED as sent
  bus::Ticks request_start = 0;
  bus::Ticks request_end = 0;         ///< end of the last stop bit
  bool expects_reply = true;          ///< false for SDN (broadcast Global_Control)
  bool answered = false;              ///< a reply started within TSL
  std::vector<std::uint8_t> response; ///< as received (corrupted octets if response_flags != 0)
  std::uint32_t response_flags = 0;   ///< bus::RxFrame flags of the reply
  bus::Ticks response_start = 0;
  bus::Ticks response_end = 0;
  std::int64_t tsdr_bits = -1;        ///< idle bit times request end → reply start; -1 = none
  std::uint8_t sender = 0;            ///< FDL address the tester used as SA
  std::string note;                   ///< what the test meant by it ("Set_Prm, wrong ident")
  bus::Baud baud = bus::Baud::k1_5M;  ///< (addition by cbat) the line's baud: times → bit times
};

/// One line's worth of bus: who may talk and how fast.
struct TestBusOptions {
  fdl::BusParams params;            ///< baud, TSL, min/max TSDR, TSYN, ...
  std::uint8_t tester_address = 1;  ///< the class-1 master the battery plays
  /// Paced: virtual time follows the wall clock at this ratio (an outside DUT behind a pty).
  /// Unset: as fast as possible (a slave model).
  std::optional<bus::Speed> paced;
  /// Wall-clock bound of one paced wait (a stalled outside program must not hang the suite).
  std::chrono::milliseconds paced_wait_limit{5000};
  std::uint64_t seed = 1;
  /// (Addition by cbat.) The tester's Data_Exchange poll interval: the battery's step helpers
  /// (conformance/src/steps.hpp data_exchange) start a Data_Exchange of the tester's own
  /// address no earlier than this after the end of its previous one. 0 = back to back.
  bus::Ticks dx_interval = 0;
};

class TestBus {
 public:
  explicit TestBus(TestBusOptions options);
  ~TestBus();
  TestBus(const TestBus&) = delete;
  TestBus& operator=(const TestBus&) = delete;

  const TestBusOptions& options() const { return m_opt; }
  bus::Baud baud() const { return m_opt.params.baud; }
  bus::Scheduler& scheduler() { return m_sched; }
  bus::Line& line() { return *m_line; }
  /// Set when paced (attach a PtyStation's I/O here).
  bus::PacedRunner* runner() { return m_runner.get(); }

  /// Attaches the device under test (after the tester on the cable). Before start().
  bus::AttachmentId attach_dut(bus::Device& dut, std::string label = "DUT");
  /// Powers the line; the DUT gets on_power_on at the current time.
  void start();
  bus::Ticks now() const;

  /// Sends `telegram` (encoded, SD..ED; its SA is the tester's address, or another one when a
  /// test plays a second master) and waits for the reply window. `not_before` delays the start.
  Exchange request(std::span<const std::uint8_t> telegram, std::string note = {},
                   std::optional<bus::Ticks> not_before = std::nullopt);
  /// Sends a telegram that gets no reply (SDN: broadcast Global_Control); waits until its end
  /// plus TSYN so the next request may follow.
  Exchange send_no_reply(std::span<const std::uint8_t> telegram, std::string note = {});
  /// Lets virtual time pass with no traffic from the tester (watchdog, Min_Slave_Interval).
  void idle(bus::Ticks duration);

  // Faults between the tester and the DUT, at the current time.
  void set_dut_power(bool on);
  void set_bus_interrupted(bool cut);

  /// Every exchange so far, in order.
  const std::vector<Exchange>& transcript() const { return m_transcript; }
  /// Frames on the line that were no reply to a request of the tester (late or unsolicited).
  struct ExtraFrame {
    std::vector<std::uint8_t> bytes;
    bus::Ticks start = 0;
    bus::Ticks end = 0;
    std::uint32_t flags = 0;
    /// Set for a line event instead of a frame ("power off DUT", "cable cut", ...); then bytes
    /// is empty and start = end = the event's time. (Addition by cbat.)
    std::string event;
  };
  const std::vector<ExtraFrame>& extra_frames() const { return m_extra; }
  /// Index into transcript() for a test's evidence: since(mark()) = what it sent after.
  std::size_t mark() const { return m_transcript.size(); }
  std::span<const Exchange> since(std::size_t mark) const;

  // --- additions (cbat) -------------------------------------------------------------------
  /// Bit times of the line's baud in `ticks` (rounded down) and back.
  std::int64_t bits(bus::Ticks ticks) const { return bus::ticks_to_bits(ticks, baud()); }
  bus::Ticks ticks(std::int64_t bits) const { return bus::bits_to_ticks(bits, baud()); }
  /// End of the last frame anyone sent on the line (the TSYN reference of the next request).
  bus::Ticks line_free_at() const;
  /// The attachment of the device under test (valid after attach_dut()).
  bus::AttachmentId dut_attachment() const { return m_dut_att; }

 private:
  class Tester;
  void run_until(bus::Ticks t, const std::function<bool()>& done);
  // Additions (cbat): the shared body of request()/send_no_reply(), and draining what the
  // tester heard outside a reply window into extra_frames().
  Exchange transmit(std::span<const std::uint8_t> telegram, std::string note,
                    std::optional<bus::Ticks> not_before, bool expects_reply);
  void settle();
  void drain_heard();

  TestBusOptions m_opt;
  bus::Scheduler m_sched;
  std::unique_ptr<bus::PacedRunner> m_runner;
  std::unique_ptr<bus::Line> m_line;
  std::unique_ptr<Tester> m_tester;
  bus::AttachmentId m_tester_att{};
  bus::AttachmentId m_dut_att{};
  bool m_dut_attached = false;
  std::vector<Exchange> m_transcript;
  std::vector<ExtraFrame> m_extra;
};

}  // namespace pbvbus::conformance
