#pragma once
// Serial PROFIBUS over a pseudo-terminal (design.md "Doors to the outside": "a pseudo-terminal
// that carries one line's raw bytes, as a station or as a monitor").
//
// A PtyStation is a Device on a line whose other side is a pty. A program (a real master's or
// slave's software, an analyzer, `cat`) opens path() (/dev/pts/N) like a serial port.
//
// Program -> line: the bytes it writes are split into telegrams by start delimiter and length
// (FrameSplitter: SC 1, SD4 3, SD1 6, SD3 14, SD2 LE+6); bytes that cannot start a telegram are
// dropped and counted. Each complete telegram is transmitted at the current virtual time, and
// never sooner than TSYN (33 bit times) of idle after the previous telegram from the pty, since
// a UART-driving station would keep that gap and stations on the line enforce it. An
// incomplete telegram that waits longer than `resync_after` (virtual time) for its remaining
// octets is dropped when the next bytes arrive, so one lost byte does not shift every telegram
// after it.
//
// Line -> program, by mode:
//  - Monitor: every frame seen on the line comes out raw, damaged ones included (a UART on a
//    real bus would deliver those bytes too).
//  - Station(address): frames whose DA is the address or 127 (requests, tokens and replies to
//    it), plus the first frame that starts within `reply_window` bit times after the end of a
//    telegram the pty sent: that is the reply to the program's request, whatever its form (SC
//    E5 has no DA). The default window is the DP default slot time TSL for the line's baud
//    (protocol-facts.md §C.1: 100..1000 bit times), which is max TSDR + margin: a reply that
//    starts later would have timed out at a real master too.
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

  struct Options {
    Mode mode = Mode::Monitor;
    int address = -1;  ///< FDL address 0..126 for Mode::Station
    /// Station mode: bit times after the end of the pty's own telegram within which a frame
    /// must start to count as its reply; 0 = default_slot_time_bits(line baud).
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

  void emit(std::span<const std::uint8_t> frame);
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
  bool m_powered = false;
  std::vector<std::uint8_t> m_out;  // backlog towards the program
  Stats m_stats;
  std::unique_ptr<Io> m_io;
};

}  // namespace pbvbus::bus
