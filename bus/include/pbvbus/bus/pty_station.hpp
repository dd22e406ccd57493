#pragma once
// Serial PROFIBUS over a pseudo-terminal (design.md "Doors to the outside": "a pseudo-terminal
// that carries one line's raw bytes, as a station or as a monitor").
//
// A PtyStation is a Device on a line whose other side is a pty. A program (a real master's or
// slave's software, an analyzer, `cat`) opens path() (/dev/pts/N) like a serial port.
//
// Program -> line: the bytes it writes are split into telegrams by start delimiter and length
// (FrameSplitter: SC 1, SD4 3, SD1 6, SD3 14, SD2 LE+6); bytes that cannot start a telegram are
// dropped and counted. An incomplete telegram that waits longer than `resync_after` (virtual
// time) for its remaining octets is dropped when the next bytes arrive, so one lost byte does
// not shift every telegram after it. When a complete telegram goes out depends on the
// attachment's timing, chosen per attachment:
//  - Timing::Interface (the default) behaves like the DP interface ASIC of a PC card: the
//    program's telegrams wait in a queue (in the order written) and each goes out at the first
//    virtual time when
//      * no other station's frame is on the line (carrier sense, DevicePort::receiving()),
//      * a request or token (any SD1/SD2/SD3 with the request bit, any SD4) finds the line idle
//        for TSYN = 33 bit times after the end of the last frame on the line, whoever sent it
//        (protocol-facts.md §A, §C.2: receivers synchronise only after TSYN idle); a response
//        or SC needs only the line to be free (it belongs to a request just heard), and
//      * after the attachment's own request that expects a reply (SDA, SRD, FDL Status, Ident,
//        LSAP status, MSRD to one station) or own token to another station, the reply (the
//        receiver's first frame) has arrived, or the slot time has passed without one
//        (`reply_window_bits`, the line's TSL in scenarios). A reply that started within the
//        slot time is awaited to its end.
//    The station tracks every frame on the line for this, whatever it forwards to the program.
//    Programs on a PC do not keep bus timing (one writes its next request a few bit times
//    after reading a reply); with this timing they need not.
//  - Timing::Raw is a plain RS-485 UART: each telegram goes out at the virtual time it arrived,
//    kept only TSYN apart from the attachment's own previous telegram. Other stations' traffic
//    is not considered, so the program's own timing is what the line sees (and what the
//    receivers judge: a request too soon after the previous frame is dropped by them). For
//    testing a stack's own timing.
// Either way, a telegram that goes out later than it arrived counts as held (Stats::held,
// hold_total, hold_max, in virtual time); in Raw mode only the gap between own telegrams holds.
// Telegrams still waiting when the station loses power are dropped (Stats::discarded).
//
// Line -> program, by mode:
//  - Monitor: every frame seen on the line comes out raw, damaged ones included (a UART on a
//    real bus would deliver those bytes too).
//  - Station(address): frames whose DA is the address or 127 (requests, tokens and replies to
//    it), plus the first frame that starts within `reply_window` bit times after the end of a
//    telegram the pty sent: that is the reply to the program's request, whatever its form (SC
//    E5 has no DA). The default window is the DP default slot time TSL for the line's baud
//    (protocol-facts.md §C.1: 100..1000 bit times), which is max TSDR + margin: a reply that
//    starts later would have timed out at a real master too. Scenarios set it to the line's
//    TSL. The same window is the slot time of the Interface timing.
// Output is written as frames are delivered, without blocking: when the program does not read
// and the pty buffer is full, up to `max_backlog` octets wait; beyond that whole frames are
// dropped and counted, and the bus never stalls.
//
// The station keeps its own handle on the slave side open, so the program may close and reopen
// the path without the master side seeing EIO or a hangup. (A program opening the pty late may
// first read frames queued earlier; like with any serial port, it should flush on open.)
//
// Timing: in paced mode a program's bytes enter at the virtual time that matches the wall clock
// when they were read. At real-time speed a program answering a request through the pty takes
// milliseconds — far beyond max TSDR at any PROFIBUS baud rate — so a program acting as a slave
// or expecting fast slaves needs a slowed-down runner (PacedRunner speed, e.g. 1/1000) or a slow
// line. Monitoring has no such limit.
//
// I/O: attach_io(runner) reads the pty when the runner's io_context says it is readable and
// injects the bytes through runner.post(); poll_input() does the same synchronously, for tests
// and the fast driver. All Device callbacks run on the runner's thread.

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/frame_splitter.hpp"
#include "pbvbus/bus/time.hpp"

namespace pbvbus::bus {

class PacedRunner;

/// The DP default slot time TSL in bit times for a baud rate (protocol-facts.md §C.1).
std::int64_t default_slot_time_bits(Baud baud);

class PtyStation final : public Device {
 public:
  enum class Mode { Monitor, Station };
  /// When the program's telegrams go on the line (see the header comment).
  enum class Timing { Interface, Raw };

  struct Options {
    Mode mode = Mode::Monitor;
    int address = -1;  ///< FDL address 0..126 for Mode::Station
    Timing timing = Timing::Interface;
    /// Bit times after the end of the pty's own telegram within which a frame must start to
    /// count as its reply (Station mode: forwarded to the program; Interface timing: the slot
    /// time awaited before the next telegram); 0 = default_slot_time_bits(line baud).
    std::int64_t reply_window_bits = 0;
    /// Virtual time after which an incomplete telegram from the program is abandoned.
    Ticks resync_after = 100 * kTicksPerMs;
    /// Octets that may wait for the program to read before frames are dropped.
    std::size_t max_backlog = 64 * 1024;
  };

  struct Stats {
    std::uint64_t frames_in = 0;       ///< telegrams from the program put on the line
    std::uint64_t bytes_in = 0;        ///< octets read from the program
    std::uint64_t garbage_bytes = 0;   ///< octets dropped while looking for a start delimiter
    std::uint64_t abandoned = 0;       ///< incomplete telegrams dropped after resync_after
    std::uint64_t frames_out = 0;      ///< frames written (or queued) to the program
    std::uint64_t bytes_out = 0;
    std::uint64_t frames_dropped = 0;  ///< frames dropped because the program does not read
    std::uint64_t octets_sent = 0;     ///< octets of the telegrams put on the line
    std::uint64_t held = 0;            ///< telegrams that went out later than they arrived
    Ticks hold_total = 0;              ///< sum of those delays (virtual time)
    Ticks hold_max = 0;                ///< the longest of them
    std::uint64_t queue_max = 0;       ///< most telegrams waiting at once
    std::uint64_t discarded = 0;       ///< telegrams dropped unsent (power loss)
  };

  /// Opens a new pty in raw mode. Throws std::system_error if that fails, std::invalid_argument
  /// for a Station without a valid address.
  explicit PtyStation(Options options);
  ~PtyStation() override;
  PtyStation(const PtyStation&) = delete;
  PtyStation& operator=(const PtyStation&) = delete;

  /// The slave side, e.g. "/dev/pts/7".
  const std::string& path() const { return m_path; }
  const Options& options() const { return m_opt; }
  Stats stats() const;

  /// Reads from the pty whenever it becomes readable on runner.io_context() and feeds the bytes
  /// in at the runner's virtual time. Call once, before running. The runner must outlive the
  /// station, or detach_io() must be called before the runner goes away.
  void attach_io(PacedRunner& runner);
  /// Stops using the runner's io_context (pending waits are cancelled).
  void detach_io();
  /// Reads whatever the program has written (waiting up to `wait` for the first byte) and feeds
  /// it in at the port's current time. Returns the number of octets read. For tests and the
  /// fast driver; do not mix with attach_io().
  std::size_t poll_input(std::chrono::milliseconds wait = std::chrono::milliseconds(0));
  /// Octets written by the line but not yet accepted by the pty.
  std::size_t backlog() const { return m_out.size(); }
  /// Telegrams from the program waiting to go on the line.
  std::size_t queued() const { return m_queue.size(); }
  /// Tries to write the backlog again (called on every output and input anyway).
  void flush_output();

  // --- Device ---------------------------------------------------------------------------------
  void on_power_on(Ticks now) override;
  void on_power_off(Ticks now) override;
  void on_frame(const RxFrame& frame) override;
  void on_timer(Ticks now) override;
  const char* kind() const override { return "pty"; }

  /// Feeds octets as if the program had written them now (what poll_input and attach_io do).
  void feed(std::span<const std::uint8_t> bytes);

 private:
  struct Io;
  struct Held {
    std::vector<std::uint8_t> bytes;
    Ticks arrived = 0;
  };

  void emit(std::span<const std::uint8_t> frame);
  /// Station/Monitor mode: passes the frame to the program if it is for it.
  void forward(const RxFrame& frame);
  /// Sends what may go out now (Interface timing) and arms the timer for the rest.
  void pump(Ticks now);
  void send(Ticks start, const Held& t);
  std::int64_t window_bits() const;
  std::size_t read_available(std::vector<std::uint8_t>& into);

  Options m_opt;
  int m_master = -1;
  int m_slave = -1;  // our own handle on the slave side: keeps the pty alive across reopen
  std::string m_path;
  FrameSplitter m_splitter;
  Ticks m_first_pending_at = 0;  // when the incomplete telegram's first octet arrived
  Ticks m_tx_free_at = 0;        // earliest start of the next telegram from the pty
  Ticks m_reply_until = -1;      // Station mode: a reply must start before this
  Ticks m_reply_after = -1;      // ... and at or after this (end of our telegram)
  // Interface timing.
  std::deque<Held> m_queue;       // telegrams from the program, oldest first
  Ticks m_line_free_at = 0;       // end of the last frame on the line (anyone's)
  bool m_await_reply = false;     // our request/token is waiting for its reply ...
  Ticks m_await_from = 0;         // ... which must start at or after this (our telegram's end)
  Ticks m_await_until = 0;        // ... and at or before this (slot time)
  bool m_powered = false;
  std::vector<std::uint8_t> m_out;  // backlog towards the program
  Stats m_stats;
  std::unique_ptr<Io> m_io;
};

}  // namespace pbvbus::bus
