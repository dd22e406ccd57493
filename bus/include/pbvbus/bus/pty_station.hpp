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
// Bounds (an interface chip has a job queue of fixed size and the PC program's requests have a
// lifetime; whatever a program writes, the station's memory stays bounded):
//  - At most `max_queue` (default 32) telegrams wait for the line. A telegram completed while
//    that many wait is dropped (Stats::dropped_full). A program that awaits each reply has one
//    telegram waiting; one that writes a cycle's requests at once, a handful. In Raw timing the
//    telegrams handed to the line but not yet started count instead.
//  - A telegram that has waited longer than `max_age_bits` (virtual time) when its turn comes is
//    dropped (Stats::dropped_stale); in Raw timing, one that would start that late. The default
//    is two of the longest request cycles, 2 x (2805 + 33 + TSL + 2805 + 33) bit times: the
//    longest telegram (255 octets = 2805 bit times) on the line, TSYN, our own request's slot
//    time TSL, the longest reply, TSYN. A program that awaits each reply never waits longer than
//    one such cycle; a telegram older than two sits behind a backlog (garbage, a program that
//    wrote far ahead), its program has given up on it (a PC master's reply timeout is longer
//    than a cycle), and sent late its reply would be taken for the reply to the retry. At the
//    DP default TSL: 11 552 bit times at 45.45 kbit/s (254 ms), 13 352 at 12 Mbit/s (1.1 ms).
//  - The program's bytes are read and split in chunks of `kReadChunk` (4096) octets; with
//    attach_io() the next chunk is read only after the previous one was fed, so a program that
//    writes faster than the station splits is slowed down by the pty, like a UART's full FIFO.
//    The splitter holds at most one incomplete telegram (255 octets); the backlog towards the
//    program at most `max_backlog` octets.
//
// Line -> program, by mode (exactly these frames, as they were on the line):
//  - Monitor: every frame seen on the line comes out raw, damaged ones included (a UART on a
//    real bus would deliver those bytes too).
//  - Station(address): frames whose DA is current_address() or 127 (requests, tokens and
//    replies to it; damaged ones included, a UART cannot tell), plus the first frame that starts
//    within `reply_window` bit times after the end of a telegram the pty sent: that is the
//    reply to the program's request, whatever its form (SC E5 has no DA). The default window is
//    the DP default slot time TSL for the line's baud (protocol-facts.md §C.1: 100..1000 bit
//    times), which is max TSDR + margin: a reply that starts later would have timed out at a
//    real master too. Scenarios set it to the line's TSL. The same window is the slot time of
//    the Interface timing. Other stations' traffic (requests to other slaves and their replies,
//    tokens between others, SC answering someone else) does not come out.
//  - Station with `forward_all`: every frame, like Monitor (a plain UART on the bus); the
//    address still decides the reply window and the Set_Slave_Add tracking below.
// Set_Slave_Add (protocol-facts.md §D.7): a request from the line to current_address() with DSAP
// 55 (SD2 or SD3, FCS and ED correct, SRD), data octet 0 = the new address 0..126, that the
// program acknowledges positively (SC E5, or an SD1 response with status OK to the requester)
// as the first telegram after it, starting within the reply window, changes the program's
// address: from then on the frames for the new address are forwarded (Stats::address_changes).
// options().address stays what was configured; current_address() goes back to it when the
// program closes the pty (a new program starts with the configured address).
// Output is written as frames are delivered, without blocking: when the program does not read
// and the pty buffer is full, up to `max_backlog` octets wait; beyond that whole frames are
// dropped and counted, and the bus never stalls.
//
// The program's open and close. The station keeps its own handle on the slave side open, so
// the program may close and reopen the path without the master side seeing EIO or a hangup
// (which also means the master side never learns of a close). It watches the slave side's
// device node with inotify (IN_OPEN, IN_CLOSE_WRITE, IN_CLOSE_NOWRITE: works on devpts; the
// station's own handle is opened before the watch and counts for nothing): every open file
// description of the node made by anyone else counts until its last close. program_open(),
// program_opens() and wait_program_open() report what has been observed.
//  - While no program has the pty open, frames for it are not written (Stats::frames_no_program).
//  - When a program opens it, whatever was written towards the program before is discarded
//    (the slave side's input is flushed, the backlog cleared): a program never reads frames from
//    before it opened.
//  - When the last program closes it: the bytes it wrote that are still unread are read and
//    split (they were written while it was open), then the telegrams still waiting for the line
//    are dropped (Stats::dropped_closed), the incomplete telegram of the splitter too (counted
//    as abandoned), the backlog and the slave side's input are cleared, and the slave side's
//    termios is set back to the raw settings of open_pty(). Otherwise the settings of the last
//    program would persist (the station's handle keeps the tty alive), and a pty ignores parity:
//    glibc's tcsetattr reads the settings back and fails with EINVAL when the parity asked for
//    did not take and the baud rate is unchanged, so a second pyserial program asking the same
//    baud and even parity as the first could not open the port (Stats::program_closes).
//    A program that writes a telegram and closes at once loses it if the line was busy: the
//    telegram needs the pty open until it is on the line.
// If inotify is not available, the station behaves as if a program always had the pty open.
//
// Timing: in paced mode a program's bytes enter at the virtual time that matches the wall clock
// when they were read. At real-time speed a program answering a request through the pty takes
// milliseconds — far beyond max TSDR at any PROFIBUS baud rate — so a program acting as a slave
// or expecting fast slaves needs a slowed-down runner (PacedRunner speed, e.g. 1/1000) or a slow
// line. Monitoring has no such limit.
//
// I/O: attach_io(runner) reads the pty when the runner's io_context says it is readable and
// injects the bytes through runner.post(); poll_input() does the same synchronously, for tests
// and the fast driver. All Device callbacks run on the runner's thread. program_open(),
// program_opens(), current_address() and wait_program_open() may be called from any thread.

#include <atomic>
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
/// The default age bound of a waiting telegram for a slot time (see the header comment):
/// 2 x (2805 + 33 + slot + 2805 + 33) bit times.
std::int64_t default_max_age_bits(std::int64_t slot_bits);

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
    /// Telegrams from the program that may wait for the line at once; more are dropped
    /// (Stats::dropped_full).
    std::size_t max_queue = 32;
    /// Bit times a telegram may have waited when its turn comes; older ones are dropped
    /// (Stats::dropped_stale). 0 = default_max_age_bits(the reply window).
    std::int64_t max_age_bits = 0;
    /// Station mode: forward every frame on the line to the program, like Monitor mode (a plain
    /// UART), instead of only its own traffic and its replies.
    bool forward_all = false;
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
    std::uint64_t dropped_full = 0;    ///< telegrams dropped: max_queue were waiting
    std::uint64_t dropped_stale = 0;   ///< telegrams dropped: older than max_age_bits
    std::uint64_t dropped_closed = 0;  ///< telegrams dropped unsent: their program closed the pty
    std::uint64_t frames_no_program = 0;  ///< frames for the program while none had it open
    std::uint64_t program_opens = 0;   ///< opens of the slave side by programs (observed)
    std::uint64_t program_closes = 0;  ///< times the last program closed it (observed, handled)
    std::uint64_t address_changes = 0;  ///< Set_Slave_Add the program acknowledged
  };

  /// Octets read from the program and split at a time (see the header comment).
  static constexpr std::size_t kReadChunk = 4096;

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

  /// Whether some process other than this station has the slave side open now, as far as the
  /// station has observed (see the header comment). Any thread.
  bool program_open() const;
  /// How many opens of the slave side by programs have been observed so far. Any thread.
  std::uint64_t program_opens() const;
  /// Blocks the calling thread up to `limit` until a program has the slave side open; returns
  /// whether one has. Works with attach_io() running on a PacedRunner's thread and without it;
  /// must not run concurrently with detach_io() or the destructor.
  bool wait_program_open(std::chrono::milliseconds limit);
  /// The program's FDL address in Station mode: options().address until the program
  /// acknowledges a Set_Slave_Add (see the header comment); -1 in Monitor mode. Any thread.
  int current_address() const { return m_address.load(std::memory_order_relaxed); }
  /// The age bound in bit times actually used (max_age_bits or its default).
  std::int64_t max_age_bits() const;

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
  struct Watch;
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
  /// Reads up to `max` octets from the master side (non-blocking).
  std::size_t read_some(std::uint8_t* into, std::size_t max);
  /// Reads and feeds up to `limit` octets in chunks; returns how many.
  std::size_t read_and_feed(std::size_t limit);
  /// Station thread: takes in the observed opens and closes and acts on them.
  void sync_program();
  void on_program_closed();
  void on_program_opened();
  /// Whether a telegram from the program answers a pending Set_Slave_Add positively.
  void check_slave_add_ack(Ticks start, std::span<const std::uint8_t> t);

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
  std::deque<Ticks> m_raw_starts;   // Raw timing: starts of telegrams handed to the line
  // The program's address and a Set_Slave_Add waiting for the program's acknowledgement.
  std::atomic<int> m_address{-1};
  int m_ssa_new = -1;       // the new address asked for, -1 = none pending
  int m_ssa_master = -1;    // who asked
  Ticks m_ssa_from = 0;     // the acknowledgement must start at or after this (request end)
  Ticks m_ssa_until = 0;    // ... and at or before this (the reply window)
  // The program's opens and closes as applied on the station's thread.
  bool m_present = false;
  std::uint64_t m_applied_opens = 0;
  std::uint64_t m_applied_zeros = 0;
  Stats m_stats;
  std::unique_ptr<Watch> m_watch;  // inotify on the slave side (shared with other threads)
  std::unique_ptr<Io> m_io;
};

}  // namespace pbvbus::bus
