// Serial PROFIBUS over a real pseudo-terminal (design.md "Serial PROFIBUS"): a test plays the
// program on the slave side of the pty; probes on the line check bytes and bit timing. Built
// also under ASan+UBSan and TSan (a door, with the program's threads: *_concurrency_test).

#include "pbvbus/bus/pty_station.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <termios.h>

#include <atomic>
#include <cstring>
#include <random>
#include <thread>

#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/paced_runner.hpp"
#include "probe.hpp"

namespace pbvbus::bus {
namespace {

using namespace std::chrono_literals;
using test::bytes_from_hex;
using test::Probe;
using test::to_hex;

constexpr Ticks kBit = 2424;  // 1.5 Mbit/s
constexpr Ticks B(std::int64_t bits) { return bits * kBit; }
constexpr const char* kFdlStatusTo3 = "10 03 01 49 4D 16";  // Request FDL Status, 1 -> 3

/// The program's end of the pty.
class Program {
 public:
  explicit Program(const std::string& path) { open(path); }
  ~Program() { close(); }
  void open(const std::string& path) {
    m_fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(m_fd, 0) << "cannot open " << path;
  }
  void close() {
    if (m_fd >= 0) ::close(m_fd);
    m_fd = -1;
  }
  void write_hex(const char* hex) {
    const auto b = bytes_from_hex(hex);
    ASSERT_EQ(::write(m_fd, b.data(), b.size()), static_cast<ssize_t>(b.size()));
  }
  /// Reads exactly n octets or whatever arrived before the timeout.
  std::string read_hex(std::size_t n, std::chrono::milliseconds timeout = 2000ms) {
    return to_hex(read_bytes(n, timeout));
  }
  std::vector<std::uint8_t> read_bytes(std::size_t n, std::chrono::milliseconds timeout = 2000ms) {
    std::vector<std::uint8_t> got;
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (got.size() < n && std::chrono::steady_clock::now() < until) {
      pollfd p{m_fd, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      std::uint8_t buf[512];
      const ssize_t r = ::read(m_fd, buf, std::min(sizeof buf, n - got.size()));
      if (r > 0) got.insert(got.end(), buf, buf + r);
    }
    return got;
  }
  /// Whether anything is readable within `wait`.
  bool readable(std::chrono::milliseconds wait = 50ms) {
    pollfd p{m_fd, POLLIN, 0};
    return ::poll(&p, 1, static_cast<int>(wait.count())) > 0;
  }

 private:
  int m_fd = -1;
};

/// Reads until `want` octets came through or 2 s passed (the pty delivers asynchronously).
std::size_t poll_until(PtyStation& pty, std::size_t want) {
  std::size_t got = 0;
  const auto until = std::chrono::steady_clock::now() + 2s;
  while (got < want && std::chrono::steady_clock::now() < until) got += pty.poll_input(20ms);
  return got;
}

class PtyTest : public ::testing::Test {
 protected:
  void make(PtyStation::Options o) {
    pty = std::make_unique<PtyStation>(o);
    line.attach(*pty, "pty");
    line.attach(master, "master");
    line.attach(slave, "slave");
    line.add_tap(rec);
    line.start();
  }
  Scheduler sched;
  Line line{sched, "A", Baud::k1_5M};
  std::unique_ptr<PtyStation> pty;
  Probe master, slave;
  test::FrameRecorder rec;
};

TEST_F(PtyTest, OpensARawPseudoTerminal) {
  make({});
  EXPECT_EQ(pty->path().rfind("/dev/pts/", 0), 0u) << pty->path();
  EXPECT_EQ(::access(pty->path().c_str(), R_OK | W_OK), 0);
  EXPECT_STREQ(pty->kind(), "pty");
  EXPECT_THROW(PtyStation({PtyStation::Mode::Station, 127}), std::invalid_argument);
  EXPECT_THROW(PtyStation({PtyStation::Mode::Station, -1}), std::invalid_argument);
}

TEST_F(PtyTest, ProgramTelegramGoesOnTheLineAtTheCurrentTime) {
  make({});
  Program prog(pty->path());
  sched.run_until(B(1000));
  prog.write_hex(kFdlStatusTo3);
  ASSERT_EQ(poll_until(*pty, 6), 6u);
  sched.run_until(B(2000));
  for (Probe* p : {&master, &slave}) {
    ASSERT_EQ(p->rx.size(), 1u);
    EXPECT_EQ(p->rx[0].hex(), kFdlStatusTo3);
    EXPECT_EQ(p->rx[0].start, B(1000));
    EXPECT_EQ(p->rx[0].end, B(1000 + 66));
    EXPECT_EQ(p->rx[0].flags, 0);
  }
  ASSERT_EQ(rec.size(), 1u);
  EXPECT_EQ(rec.frame(0).sender, 0);
  EXPECT_EQ(pty->stats().frames_in, 1u);
  EXPECT_EQ(pty->stats().bytes_in, 6u);
  EXPECT_EQ(pty->stats().garbage_bytes, 0u);
}

TEST_F(PtyTest, RawTelegramsWrittenAtOnceKeepTsynBetweenThem) {
  PtyStation::Options o;
  o.timing = PtyStation::Timing::Raw;
  make(o);
  Program prog(pty->path());
  prog.write_hex("10 03 01 49 4D 16 DC 05 01 E5");
  ASSERT_EQ(poll_until(*pty, 10), 10u);
  sched.run_until(B(1000));
  ASSERT_EQ(rec.size(), 3u);
  EXPECT_EQ(rec.hex_all(), (std::vector<std::string>{kFdlStatusTo3, "DC 05 01", "E5"}));
  EXPECT_EQ(rec.gap_bits(1), 33);
  EXPECT_EQ(rec.gap_bits(2), 33);
  EXPECT_EQ(rec.start_bits(0), 0);  // at once
}

TEST_F(PtyTest, GarbageBeforeATelegramIsSkippedAndCounted) {
  make({});
  Program prog(pty->path());
  prog.write_hex("FF 00 16 68 03 03 68 10 03 01 49 4D 16");
  ASSERT_EQ(poll_until(*pty, 13), 13u);
  sched.run_until(B(1000));
  ASSERT_EQ(rec.size(), 1u);
  EXPECT_EQ(rec.hex(0), kFdlStatusTo3);
  EXPECT_EQ(pty->stats().garbage_bytes, 7u);
}

TEST_F(PtyTest, AbandonsAnIncompleteTelegramAfterAPause) {
  PtyStation::Options o;
  o.resync_after = 100 * kTicksPerMs;
  make(o);
  Program prog(pty->path());
  prog.write_hex("10 03 01");  // the rest never comes
  ASSERT_EQ(poll_until(*pty, 3), 3u);
  sched.run_until(200 * kTicksPerMs);
  prog.write_hex(kFdlStatusTo3);
  ASSERT_EQ(poll_until(*pty, 6), 6u);
  sched.run_until(300 * kTicksPerMs);
  ASSERT_EQ(rec.size(), 1u);
  EXPECT_EQ(rec.hex(0), kFdlStatusTo3);
  EXPECT_EQ(pty->stats().abandoned, 1u);
  EXPECT_EQ(pty->stats().garbage_bytes, 3u);
}

TEST_F(PtyTest, MonitorPassesEveryFrameRaw) {
  make({});
  Program prog(pty->path());
  master.send(B(10), "10 05 01 49 4F 16");
  slave.send(B(100), "E5");
  master.send(B(200), "68 05 05 68 8A 81 6D 3C 3E F2 16");
  sched.run_until(B(1000));
  EXPECT_EQ(prog.read_hex(18), "10 05 01 49 4F 16 E5 68 05 05 68 8A 81 6D 3C 3E F2 16");
  EXPECT_EQ(pty->stats().frames_out, 3u);
}

TEST_F(PtyTest, StationGetsItsOwnTrafficAndTheReplyToItsRequest) {
  make({PtyStation::Mode::Station, 3});
  Program prog(pty->path());
  master.send(B(10), kFdlStatusTo3);          // to 3: out
  master.send(B(100), "10 04 01 49 4E 16");   // to 4: not out
  master.send(B(200), "10 7F 01 44 C4 16");   // broadcast: out
  master.send(B(300), "DC 03 01");            // token to 3: out
  master.send(B(400), "E5");                  // SC, not after a request of ours: not out
  sched.run_until(B(1000));
  EXPECT_EQ(prog.read_hex(15), "10 03 01 49 4D 16 10 7F 01 44 C4 16 DC 03 01");
  EXPECT_FALSE(prog.readable());

  // The program sends a request to 4; station 4 answers with SC after 11 bits: the reply comes
  // out. A later SC (outside the reply window of 300 bit times at 1.5M) does not.
  slave.on_rx = [&](const RxFrame& f) {
    if (to_hex(f.bytes) == "10 04 03 49 50 16") slave.send(f.end + B(11), "E5");
  };
  prog.write_hex("10 04 03 49 50 16");
  ASSERT_EQ(poll_until(*pty, 6), 6u);
  const Ticks sent = sched.now();
  sched.run_until(sent + B(500));
  master.send(sent + B(600), "E5");
  sched.run_until(sent + B(1000));
  EXPECT_EQ(prog.read_hex(1), "E5");
  EXPECT_FALSE(prog.readable());
}

TEST_F(PtyTest, ReplyWindowIsTheSlotTime) {
  PtyStation::Options o{PtyStation::Mode::Station, 3};
  o.timing = PtyStation::Timing::Raw;  // the telegram goes out at 0, when it is fed
  o.reply_window_bits = 50;
  make(o);
  Program prog(pty->path());
  prog.write_hex("10 04 03 49 50 16");
  ASSERT_EQ(poll_until(*pty, 6), 6u);
  const Ticks end = sched.now() + B(66);
  master.send(end + B(51), "E5");  // too late
  sched.run_until(end + B(500));
  EXPECT_FALSE(prog.readable());
  EXPECT_EQ(default_slot_time_bits(Baud::k1_5M), 300);
  EXPECT_EQ(default_slot_time_bits(Baud::k12M), 1000);
  EXPECT_EQ(default_slot_time_bits(Baud::k187_5), 100);
}

TEST_F(PtyTest, ProgramMayCloseAndReopenThePath) {
  make({});
  {
    Program prog(pty->path());
    prog.write_hex(kFdlStatusTo3);
    ASSERT_EQ(poll_until(*pty, 6), 6u);
  }  // closed: the station keeps the pty alive
  master.send(B(500), "E5");  // written while nobody has it open
  sched.run_until(B(1000));
  EXPECT_EQ(pty->poll_input(20ms), 0u) << "no EIO/hangup on the master side";
  Program again(pty->path());
  EXPECT_FALSE(again.readable()) << "a program never reads frames from before it opened";
  EXPECT_EQ(pty->stats().frames_no_program, 1u);
  EXPECT_EQ(pty->stats().program_closes, 1u);
  again.write_hex("DC 05 01");
  ASSERT_EQ(poll_until(*pty, 3), 3u);
  master.send(B(2000), "10 05 01 49 4F 16");
  sched.run_until(B(3000));
  EXPECT_EQ(again.read_hex(6), "10 05 01 49 4F 16");
  ASSERT_EQ(slave.rx.size(), 4u);  // pty SD1, master SC, pty token, master SD1
  EXPECT_EQ(slave.rx[2].hex(), "DC 05 01");
  EXPECT_EQ(pty->stats().program_opens, 2u);
}

TEST_F(PtyTest, ProgramThatDoesNotReadNeverStallsTheBus) {
  PtyStation::Options o;
  o.max_backlog = 1024;
  make(o);
  Program prog(pty->path());  // opened, never read
  // 1000 of the longest telegrams (255 octets, LE 249): far more than any tty buffer holds.
  std::vector<std::uint8_t> longest(255, 0x00);
  longest[0] = longest[3] = 0x68;
  longest[1] = longest[2] = 249;
  longest[4] = 3;
  longest[254] = 0x16;
  constexpr int kFrames = 1000;
  for (int i = 0; i < kFrames; ++i) master.send(B((255 * 11 + 100) * i), longest);
  sched.run_until(B((255 * 11 + 100) * kFrames));
  EXPECT_EQ(slave.rx.size(), static_cast<std::size_t>(kFrames));
  const auto s = pty->stats();
  EXPECT_GT(s.frames_dropped, 0u);
  EXPECT_EQ(s.frames_out + s.frames_dropped, static_cast<std::uint64_t>(kFrames));
  EXPECT_LE(pty->backlog(), 1024u);
  // What did get through is whole telegrams, in order: drain the tty and the backlog.
  std::vector<std::uint8_t> all;
  for (int i = 0; i < 500 && (prog.readable(20ms) || pty->backlog() > 0); ++i) {
    const auto chunk = prog.read_bytes(1 << 16, 20ms);
    all.insert(all.end(), chunk.begin(), chunk.end());
    pty->flush_output();
  }
  EXPECT_EQ(pty->backlog(), 0u);
  ASSERT_EQ(all.size(), s.frames_out * 255);
  for (std::size_t i = 0; i < all.size(); i += 255) {
    ASSERT_EQ(to_hex(std::span(all).subspan(i, 5)), "68 F9 F9 68 03") << "telegram at octet " << i;
  }
}

// --- Interface timing (the default): the attachment keeps bus timing for the program --------
// Bit times at 1.5 Mbit/s; the pty is station 3, the probes play a master and a slave.

constexpr const char* kPtyTo4 = "10 04 03 49 50 16";  // Request FDL Status, 3 -> 4 (66 bit times)
constexpr const char* kPtyTo5 = "10 05 03 49 51 16";  // Request FDL Status, 3 -> 5

class PtyTiming : public PtyTest {
 protected:
  /// Feeds `hex` as if the program had written it at exactly `at`.
  void feed_at(Ticks at, std::string hex) {
    sched.schedule(at, [this, h = std::move(hex)] { pty->feed(bytes_from_hex(h)); });
  }
  static PtyStation::Options station(PtyStation::Timing t = PtyStation::Timing::Interface) {
    PtyStation::Options o{PtyStation::Mode::Station, 3};
    o.timing = t;
    return o;
  }
};

TEST_F(PtyTiming, InterfaceIsTheDefault) {
  EXPECT_EQ(PtyStation::Options{}.timing, PtyStation::Timing::Interface);
}

TEST_F(PtyTiming, RequestFedFiveBitTimesAfterAFrameGoesOutAtItsEndPlusTsyn) {
  make(station());
  master.send(B(100), "10 05 01 49 4F 16");  // B(100) .. B(166)
  feed_at(B(171), kPtyTo4);                  // only 5 bit times of idle so far
  sched.run_until(B(1000));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(1).sender, 0);
  EXPECT_EQ(rec.hex(1), kPtyTo4);
  EXPECT_EQ(rec.frame(1).start, B(166 + 33));
  ASSERT_EQ(slave.rx.size(), 2u);
  EXPECT_EQ(slave.rx[1].idle_before, B(33));
  const auto s = pty->stats();
  EXPECT_EQ(s.frames_in, 1u);
  EXPECT_EQ(s.octets_sent, 6u);
  EXPECT_EQ(s.held, 1u);
  EXPECT_EQ(s.hold_total, B(28));
  EXPECT_EQ(s.hold_max, B(28));
  EXPECT_EQ(pty->queued(), 0u);
}

TEST_F(PtyTiming, RequestAfterEnoughIdleGoesOutAtOnce) {
  make(station());
  master.send(B(100), "10 05 01 49 4F 16");
  feed_at(B(166 + 40), kPtyTo4);
  sched.run_until(B(1000));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(1).start, B(206));
  EXPECT_EQ(pty->stats().held, 0u);
  EXPECT_EQ(pty->stats().hold_total, 0);
}

TEST_F(PtyTiming, NeverSendsWhileAnotherStationsFrameIsOnTheLine) {
  make(station());
  // A 20-octet SD2 from the master: B(1000) .. B(1220). The program writes in the middle of it,
  // after plenty of idle before it started.
  master.send(B(1000), "68 0E 0E 68 05 01 7D 00 01 02 03 04 05 06 07 08 09 0A BA 16");
  feed_at(B(1100), kPtyTo4);
  sched.run_until(B(2000));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(0).flags, 0);
  EXPECT_EQ(rec.frame(1).flags, 0);
  EXPECT_EQ(rec.frame(1).start, B(1220 + 33));
  EXPECT_EQ(pty->stats().hold_max, B(153));
}

TEST_F(PtyTiming, ResponseGoesOutWithoutTsyn) {
  // A program acting as a responder: its SC belongs to the request it just heard, which needs
  // no idle time before it (only the line must be free).
  make(station());
  master.send(B(100), "10 03 01 49 4D 16");  // to the pty: B(100) .. B(166)
  feed_at(B(150), "E5");                     // written while the request is still on the line
  sched.run_until(B(1000));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.hex(1), "E5");
  EXPECT_EQ(rec.frame(1).start, B(166));
}

TEST_F(PtyTiming, AfterItsRequestItWaitsForTheReply) {
  make(station());
  // Station 4 answers SC 11 bit times after the request.
  slave.on_rx = [&](const RxFrame& f) {
    if (to_hex(f.bytes) == kPtyTo4) slave.send(f.end + B(11), "E5");
  };
  feed_at(B(1000), std::string(kPtyTo4) + " " + kPtyTo5);  // two telegrams in one write
  sched.run_until(B(2000));
  ASSERT_EQ(rec.size(), 3u);
  EXPECT_EQ(rec.frame(0).start, B(1000));           // idle since power-on: at once
  EXPECT_EQ(rec.frame(1).start, B(1066 + 11));      // the reply
  EXPECT_EQ(rec.hex(2), kPtyTo5);
  EXPECT_EQ(rec.frame(2).start, B(1088 + 33));      // TSYN after the reply
  const auto s = pty->stats();
  EXPECT_EQ(s.queue_max, 2u);
  EXPECT_EQ(s.held, 1u);
  EXPECT_EQ(s.hold_max, B(121));
}

TEST_F(PtyTiming, WithoutAReplyItWaitsTheSlotTime) {
  make(station());  // nobody answers; slot time = the 1.5M default, 300 bit times
  feed_at(B(1000), std::string(kPtyTo4) + " " + kPtyTo5);
  sched.run_until(B(3000));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(1).start, B(1066 + 300));
}

TEST_F(PtyTiming, SlotTimeIsTheReplyWindow) {
  PtyStation::Options o = station();
  o.reply_window_bits = 100;
  make(o);
  feed_at(B(1000), std::string(kPtyTo4) + " " + kPtyTo5);
  sched.run_until(B(3000));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(1).start, B(1066 + 100));
}

TEST_F(PtyTiming, AReplyStartedWithinTheSlotTimeIsAwaitedToItsEnd) {
  make(station());
  // Station 4 answers late but in time: 290 bit times after the request, 20 octets long.
  slave.on_rx = [&](const RxFrame& f) {
    if (to_hex(f.bytes) == kPtyTo4)
      slave.send(f.end + B(290), "68 0E 0E 68 03 04 08 00 01 02 03 04 05 06 07 08 09 0A 46 16");
  };
  feed_at(B(1000), std::string(kPtyTo4) + " " + kPtyTo5);
  sched.run_until(B(3000));
  ASSERT_EQ(rec.size(), 3u);
  EXPECT_EQ(rec.frame(1).start, B(1066 + 290));
  EXPECT_EQ(rec.frame(2).start, B(1066 + 290 + 220 + 33));
  EXPECT_EQ(rec.frame(2).flags, 0);
}

TEST_F(PtyTiming, NoReplyIsAwaitedAfterABroadcastOrAResponse) {
  make(station());
  // SDN broadcast (Global_Control-like SD1) then a request: only TSYN between them.
  feed_at(B(1000), "10 7F 03 44 C6 16 " + std::string(kPtyTo4));
  sched.run_until(B(2000));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(1).start, B(1066 + 33));
}

TEST_F(PtyTiming, TokenToAnotherStationWaitsForItsActivity) {
  make(station());
  feed_at(B(1000), "DC 01 03 " + std::string(kPtyTo4));  // token to 1 (33 bit times)
  master.on_rx = [&](const RxFrame& f) {
    if (to_hex(f.bytes) == "DC 01 03") master.send(f.end + B(50), "10 05 01 49 4F 16");
  };
  sched.run_until(B(2000));
  ASSERT_EQ(rec.size(), 3u);
  EXPECT_EQ(rec.frame(1).start, B(1033 + 50));     // the new token holder's first frame
  EXPECT_EQ(rec.frame(2).start, B(1083 + 66 + 33));
}

TEST_F(PtyTiming, PowerLossDropsWaitingTelegrams) {
  make(station());
  feed_at(B(1000), std::string(kPtyTo4) + " " + kPtyTo5);
  sched.schedule(B(1100), [this] { line.set_power(0, false); });
  sched.run_until(B(3000));
  EXPECT_EQ(rec.size(), 1u);
  EXPECT_EQ(pty->stats().discarded, 1u);
  EXPECT_EQ(pty->queued(), 0u);
}

TEST_F(PtyTiming, RawSendsAtOnceWhateverIsOnTheLine) {
  make(station(PtyStation::Timing::Raw));
  master.send(B(100), "10 05 01 49 4F 16");  // B(100) .. B(166)
  feed_at(B(171), kPtyTo4);                  // 5 bit times later: out at once
  sched.run_until(B(1000));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(1).start, B(171));
  ASSERT_EQ(slave.rx.size(), 2u);
  EXPECT_EQ(slave.rx[1].idle_before, B(5));  // what a receiver will judge (and drop)
  EXPECT_EQ(pty->stats().held, 0u);
  // Even during another station's frame (a collision, as with a plain UART).
  master.send(B(2000), "68 0E 0E 68 05 01 7D 00 01 02 03 04 05 06 07 08 09 0A BA 16");
  feed_at(B(2100), kPtyTo5);
  sched.run_until(B(3000));
  ASSERT_EQ(rec.size(), 4u);
  EXPECT_EQ(rec.frame(2).sender, 0);  // taps see frames in the order they end
  EXPECT_EQ(rec.frame(2).start, B(2100));
  EXPECT_NE(rec.frame(2).flags & kRxCollision, 0);
}

// --- Bounds: the queue, the age, memory ---------------------------------------------------

TEST_F(PtyTiming, TheQueueIsBoundedAndFullDropsAreCounted) {
  PtyStation::Options o = station();
  o.max_queue = 8;
  make(o);
  std::string many;
  for (int i = 0; i < 100; ++i) many += std::string(kPtyTo4) + " ";
  feed_at(B(1000), many);
  sched.run_until(B(1001));
  EXPECT_EQ(pty->stats().dropped_full, 92u);
  EXPECT_EQ(pty->stats().queue_max, 8u);
  EXPECT_EQ(pty->queued(), 7u);  // the first is on the line
  sched.run_until(B(10000));     // each after the slot time of the one before: all within the age
  EXPECT_EQ(rec.size(), 8u);
  EXPECT_EQ(pty->stats().dropped_stale, 0u);
}

TEST_F(PtyTiming, TelegramsOlderThanTheAgeAreDroppedWhenTheirTurnComes) {
  PtyStation::Options o = station();
  o.max_age_bits = 200;
  make(o);  // nobody answers: each request waits the slot time, 300 bit times
  feed_at(B(1000), std::string(kPtyTo4) + " " + kPtyTo5 + " " + kPtyTo4);
  sched.run_until(B(5000));
  ASSERT_EQ(rec.size(), 1u);
  EXPECT_EQ(rec.frame(0).start, B(1000));
  EXPECT_EQ(pty->stats().dropped_stale, 2u);  // at B(1366) both had waited 366 bit times
  EXPECT_EQ(pty->queued(), 0u);
  // The default: two of the longest request cycles.
  EXPECT_EQ(default_max_age_bits(300), 2 * (2805 + 33 + 300 + 2805 + 33));
}

TEST_F(PtyTiming, DefaultAgeIsTwoLongestRequestCycles) {
  make(station());
  EXPECT_EQ(pty->max_age_bits(), 2 * (2805 + 33 + 300 + 2805 + 33));
  // A request that waits one slot time behind our previous one is well within it.
  feed_at(B(1000), std::string(kPtyTo4) + " " + kPtyTo5);
  sched.run_until(B(3000));
  EXPECT_EQ(rec.size(), 2u);
  EXPECT_EQ(pty->stats().dropped_stale, 0u);
}

TEST_F(PtyTiming, RawTimingIsBoundedToo) {
  PtyStation::Options o = station(PtyStation::Timing::Raw);
  o.max_queue = 4;
  make(o);
  std::string many;
  for (int i = 0; i < 10; ++i) many += std::string(kPtyTo4) + " ";
  feed_at(B(1000), many);  // one at once, four handed to the line for later, five dropped
  sched.run_until(B(5000));
  EXPECT_EQ(rec.size(), 5u);
  EXPECT_EQ(pty->stats().dropped_full, 5u);
  EXPECT_EQ(rec.gap_bits(1), 33);
}

TEST_F(PtyTest, AGarbageFloodKeepsTheStationBounded) {
  PtyStation::Options o{PtyStation::Mode::Station, 1};
  make(o);
  Program prog(pty->path());
  constexpr std::size_t kFlood = 1 << 20;
  std::vector<std::uint8_t> junk(kFlood);
  std::mt19937 rng(7);
  for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
  // The program writes the flood through its own descriptor (blocking writes in a thread).
  int wfd = ::open(pty->path().c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
  ASSERT_GE(wfd, 0);
  std::thread flood([&] {
    std::size_t done = 0;
    while (done < junk.size()) {
      const ssize_t n = ::write(wfd, junk.data() + done, junk.size() - done);
      if (n > 0) done += static_cast<std::size_t>(n);
      else if (n < 0 && errno != EINTR) break;
    }
  });
  std::size_t got = 0, max_queued = 0;
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (got < kFlood && std::chrono::steady_clock::now() < until) {
    got += pty->poll_input(20ms);
    max_queued = std::max(max_queued, pty->queued());
    sched.run_until(sched.now() + B(2000));  // the line carries what it can meanwhile
  }
  flood.join();
  ::close(wfd);
  EXPECT_EQ(got, kFlood);
  EXPECT_LE(max_queued, o.max_queue);
  const auto s = pty->stats();
  EXPECT_EQ(s.bytes_in, kFlood);
  EXPECT_GT(s.dropped_full, 0u);
  EXPECT_LE(s.queue_max, o.max_queue);
  // After the flood the queue is empty within the age bound (plus one telegram and its slot time).
  sched.run_until(sched.now() + B(pty->max_age_bits() + 2805 + 33 + 300));
  EXPECT_EQ(pty->queued(), 0u);
}

// --- The program's open and close ------------------------------------------------------------

TEST_F(PtyTest, SeesTheProgramOpenAndClose) {
  make({});
  EXPECT_FALSE(pty->program_open());
  EXPECT_EQ(pty->program_opens(), 0u);
  EXPECT_FALSE(pty->wait_program_open(30ms));
  {
    Program prog(pty->path());
    EXPECT_TRUE(pty->program_open());
    EXPECT_EQ(pty->program_opens(), 1u);
    EXPECT_TRUE(pty->wait_program_open(0ms));
  }
  EXPECT_FALSE(pty->program_open());
  std::thread later([&] {
    std::this_thread::sleep_for(30ms);
    Program prog(pty->path());
    std::this_thread::sleep_for(200ms);
  });
  EXPECT_TRUE(pty->wait_program_open(5000ms));
  later.join();
  EXPECT_EQ(pty->program_opens(), 2u);
  EXPECT_FALSE(pty->program_open());
  EXPECT_EQ(pty->poll_input(), 0u);
  EXPECT_EQ(pty->stats().program_closes, 1u) << "both closes seen in one go: the last one counts";
}

TEST_F(PtyTest, WaitProgramOpenWorksWithThePacedRunner) {
  make({});
  PacedRunner runner(sched);
  pty->attach_io(runner);
  std::atomic<bool> opened{false};
  std::thread waiter([&] { opened = pty->wait_program_open(5000ms); });
  std::thread program([&] {
    while (!runner.running()) std::this_thread::sleep_for(1ms);
    std::this_thread::sleep_for(20ms);
    Program prog(pty->path());
    std::this_thread::sleep_for(50ms);
  });
  runner.run_for(150 * kTicksPerMs);
  program.join();
  waiter.join();
  EXPECT_TRUE(opened);
  EXPECT_EQ(pty->stats().program_opens, 1u);
  EXPECT_EQ(pty->stats().program_closes, 1u);
  pty->detach_io();
}

TEST_F(PtyTest, ClosingDropsWhatWaitsAndRestoresTheTermios) {
  make({PtyStation::Mode::Station, 3});
  termios pristine{};
  {
    Program probe(pty->path());
  }
  pty->poll_input();
  const int fd0 = ::open(pty->path().c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(fd0, 0);
  ASSERT_EQ(::tcgetattr(fd0, &pristine), 0);
  // The program sets its own baud rate, writes two requests (nobody answers: the second waits
  // the slot time) and half a telegram, and closes.
  termios t = pristine;
  ::cfsetispeed(&t, B19200);
  ::cfsetospeed(&t, B19200);
  t.c_cflag |= PARENB;
  ASSERT_EQ(::tcsetattr(fd0, TCSANOW, &t), 0);
  sched.run_until(B(1000));
  const auto req = bytes_from_hex(std::string(kPtyTo4) + " " + kPtyTo4 + " 10 04");
  ASSERT_EQ(::write(fd0, req.data(), req.size()), static_cast<ssize_t>(req.size()));
  ::close(fd0);
  pty->poll_input();  // sees the close: takes in what it wrote, then drops what still waits
  master.send(B(2000), "10 03 01 49 4D 16");  // for the program, but it is gone
  sched.run_until(B(3000));
  const auto s = pty->stats();
  EXPECT_EQ(s.frames_in, 1u) << "the first went out when read (the line was idle)";
  EXPECT_EQ(s.dropped_closed, 1u);
  EXPECT_EQ(s.abandoned, 1u);
  EXPECT_EQ(pty->queued(), 0u);
  EXPECT_EQ(s.frames_no_program, 1u);
  Program next(pty->path());
  EXPECT_FALSE(next.readable());
  const int fd1 = ::open(pty->path().c_str(), O_RDWR | O_NOCTTY);
  termios now{};
  ASSERT_EQ(::tcgetattr(fd1, &now), 0);
  ::close(fd1);
  EXPECT_EQ(::cfgetospeed(&now), ::cfgetospeed(&pristine));
  EXPECT_EQ(now.c_cflag, pristine.c_cflag);
  // So a program asking for the same baud and parity as the last one can set them.
  const int fd2 = ::open(pty->path().c_str(), O_RDWR | O_NOCTTY);
  EXPECT_EQ(::tcsetattr(fd2, TCSANOW, &t), 0) << std::strerror(errno);
  ::close(fd2);
}

// --- Which frames the program sees; Set_Slave_Add --------------------------------------------

/// "68 LE LE 68 <body> FCS 16" for a body given in hex.
std::string sd2(const std::string& body_hex) {
  const auto body = bytes_from_hex(body_hex);
  unsigned sum = 0;
  for (auto b : body) sum += b;
  char head[32], tail[16];
  std::snprintf(head, sizeof head, "68 %02X %02X 68 ", unsigned(body.size()), unsigned(body.size()));
  std::snprintf(tail, sizeof tail, " %02X 16", sum & 0xFF);
  return head + body_hex + tail;
}

TEST_F(PtyTiming, FollowsAnAcknowledgedSetSlaveAdd) {
  make(station());
  Program prog(pty->path());
  EXPECT_EQ(pty->current_address(), 3);
  // Master 1 -> 3: Set_Slave_Add to 9 (DSAP 55, SSAP 62, ident 0x0A01, No_Add_Chg 0).
  const std::string ssa = sd2("83 81 6D 37 3E 09 0A 01 00");
  master.send(B(100), ssa);
  const Ticks end = B(100 + 15 * 11);
  feed_at(end + B(20), "E5");  // the program acknowledges within the slot time
  sched.run_until(B(1000));
  EXPECT_EQ(pty->current_address(), 9);
  EXPECT_EQ(pty->options().address, 3);
  EXPECT_EQ(pty->stats().address_changes, 1u);
  EXPECT_EQ(prog.read_hex(15), ssa);
  master.send(B(1000), "10 09 01 49 53 16");  // to 9: out
  master.send(B(1100), kFdlStatusTo3);         // to 3: no longer
  sched.run_until(B(2000));
  EXPECT_EQ(prog.read_hex(6), "10 09 01 49 53 16");
  EXPECT_FALSE(prog.readable());
  // A late acknowledgement (after the slot time) changes nothing.
  master.send(B(2000), sd2("89 81 6D 37 3E 0A 0A 01 00"));
  feed_at(B(2000 + 165 + 301), "E5");
  sched.run_until(B(3000));
  EXPECT_EQ(pty->current_address(), 9);
  // When the program closes, the station goes back to the configured address.
  prog.close();
  pty->poll_input();
  EXPECT_EQ(pty->current_address(), 3);
}

TEST_F(PtyTiming, IgnoresSetSlaveAddThatIsRefusedOrBroken) {
  make(station());
  // Refused: the program answers with an SD1 response "RS" (0x03).
  master.send(B(100), sd2("83 81 6D 37 3E 09 0A 01 00"));
  feed_at(B(100 + 165 + 11), "10 01 03 03 07 16");
  sched.run_until(B(1000));
  EXPECT_EQ(pty->current_address(), 3);
  // Bad FCS: not a request at all.
  master.send(B(1000), "68 09 09 68 83 81 6D 37 3E 09 0A 01 00 00 16");
  feed_at(B(1000 + 165 + 11), "E5");
  sched.run_until(B(2000));
  EXPECT_EQ(pty->current_address(), 3);
  // An SD1 acknowledgement with status OK counts.
  master.send(B(2000), sd2("83 81 6D 37 3E 0B 0A 01 00"));
  feed_at(B(2000 + 165 + 11), "10 01 03 00 04 16");
  sched.run_until(B(3000));
  EXPECT_EQ(pty->current_address(), 11);
}

TEST_F(PtyTest, ForwardAllGivesTheProgramEveryFrame) {
  PtyStation::Options o{PtyStation::Mode::Station, 3};
  o.forward_all = true;
  make(o);
  Program prog(pty->path());
  master.send(B(10), "10 04 01 49 4E 16");  // to 4
  slave.send(B(100), "E5");                  // someone else's SC
  sched.run_until(B(1000));
  EXPECT_EQ(prog.read_hex(7), "10 04 01 49 4E 16 E5");
}

TEST_F(PtyTest, PacedRunnerReadsThePtyAndWritesToIt) {
  make({});
  PacedRunner runner(sched);
  pty->attach_io(runner);
  Program prog(pty->path());
  Ticks got_at = -1;
  master.on_rx = [&](const RxFrame& f) {
    got_at = f.start;
    master.send(f.end + B(11), "E5");
  };
  std::thread program([&] {
    while (!runner.running()) std::this_thread::sleep_for(1ms);
    std::this_thread::sleep_for(30ms);
    prog.write_hex(kFdlStatusTo3);
  });
  runner.run_for(150 * kTicksPerMs);
  program.join();
  ASSERT_EQ(master.rx.size(), 1u);
  EXPECT_EQ(master.rx[0].hex(), kFdlStatusTo3);
  EXPECT_GE(got_at, 25 * kTicksPerMs) << "entered at the virtual time of its wall time";
  EXPECT_EQ(prog.read_hex(1), "E5");
  pty->detach_io();  // the runner goes first
}

}  // namespace
}  // namespace pbvbus::bus
