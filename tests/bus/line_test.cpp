// The RS-485 line model (design.md "The line", "Taps"): delivery timing in bit times, idle
// before each frame, receive filters, collisions, noise and every fault with its repair.
// Golden frames are written by hand from protocol-facts.md §B (FCS summed by hand).

#include "pbvbus/bus/line.hpp"

#include <gtest/gtest.h>

#include <memory>

#include "frame_recorder.hpp"
#include "hex.hpp"
#include "probe.hpp"

namespace pbvbus::test {
namespace {

using bus::Baud;
using bus::kIdleForever;
using bus::LineEventKind;
using bus::Ticks;

// Request FDL Status from 3, sent by 1: 10 DA SA FC FCS ED, FCS = 03+01+49 = 4D.
constexpr const char* kSd1 = "10 03 01 49 4D 16";
// Slave_Diag request from S11 (protocol-facts.md §0): 11 octets, DA 0x8A = 10 with extension.
constexpr const char* kSd2 = "68 05 05 68 8A 81 6D 3C 3E F2 16";
constexpr const char* kSc = "E5";
constexpr const char* kToken = "DC 05 01";

class LineTest : public ::testing::Test {
 protected:
  static constexpr Baud kBaud = Baud::k1_5M;
  static constexpr Ticks kBit = 2424;
  static constexpr Ticks B(std::int64_t bits) { return bits * kBit; }

  /// Attaches n receive-all probes (plus any made by the test) and the recorder.
  void make(int n) {
    for (int i = 0; i < n; ++i) {
      probes.push_back(std::make_unique<Probe>());
      line.attach(*probes.back(), "p" + std::to_string(i));
    }
  }
  Probe& p(int i) { return *probes.at(static_cast<std::size_t>(i)); }
  void at(Ticks t, std::function<void()> fn) { sched.schedule(t, std::move(fn)); }

  bus::Scheduler sched;
  bus::Line line{sched, "A", kBaud, 7};
  FrameRecorder rec;
  std::vector<std::unique_ptr<Probe>> probes;

  void SetUp() override { line.add_tap(rec); }
};

TEST_F(LineTest, FrameArrivesAfterElevenBitTimesPerOctetAtEveryOtherStation) {
  make(3);
  line.start();
  std::vector<Ticks> delivered_at;
  p(1).on_rx = [&](const bus::RxFrame&) { delivered_at.push_back(sched.now()); };
  p(0).send(B(100), kSd1);
  sched.run_until(B(1000));

  ASSERT_EQ(p(1).rx.size(), 1u);
  ASSERT_EQ(p(2).rx.size(), 1u);
  EXPECT_TRUE(p(0).rx.empty()) << "a station never receives its own frame";
  for (int i : {1, 2}) {
    const auto& r = p(i).rx[0];
    EXPECT_EQ(r.hex(), kSd1);
    EXPECT_EQ(r.start, B(100));
    EXPECT_EQ(r.end, B(100 + 6 * 11));
    EXPECT_EQ(r.idle_before, kIdleForever) << "first activity since power-on";
    EXPECT_EQ(r.flags, 0);
  }
  EXPECT_EQ(delivered_at, std::vector<Ticks>{B(166)});

  ASSERT_EQ(rec.size(), 1u);
  EXPECT_EQ(rec.hex(0), kSd1);
  EXPECT_EQ(rec.frame(0).start, B(100));
  EXPECT_EQ(rec.frame(0).end, B(166));
  EXPECT_EQ(rec.frame(0).sender, 0);
  EXPECT_EQ(rec.frame(0).sent_len, 6u);
  EXPECT_EQ(rec.frame(0).flags, 0);
  EXPECT_EQ(line.stats().frames, 1u);
  EXPECT_EQ(line.stats().octets, 6u);
}

TEST_F(LineTest, TimingHoldsAtTwelveMegabit) {
  bus::Line fast(sched, "F", Baud::k12M);
  Probe a, b;
  fast.attach(a);
  fast.attach(b);
  fast.start();
  a.send(1000, kSd2);
  sched.run_until(bus::kTicksPerMs);
  ASSERT_EQ(b.rx.size(), 1u);
  EXPECT_EQ(b.rx[0].end - b.rx[0].start, 11 * 11 * 303);
  EXPECT_EQ(b.rx[0].hex(), kSd2);
}

TEST_F(LineTest, IdleBeforeCountsFromTheLastActivityEachStationHeard) {
  make(3);
  line.start();
  // Station 1 answers everything with SC after 11 bit times (a TSDR), once.
  p(1).on_rx = [&](const bus::RxFrame& f) {
    if (p(1).rx.size() == 1) p(1).send(f.end + B(11), kSc);
  };
  p(0).send(B(0), kSd1);                 // [0, 66)
  p(0).send(B(66 + 11 + 11 + 40), kToken);  // SC is [77, 88); token 40 bits after it
  sched.run_until(B(1000));

  ASSERT_EQ(p(2).rx.size(), 3u);
  EXPECT_EQ(p(2).rx[0].idle_before, kIdleForever);
  EXPECT_EQ(p(2).rx[1].hex(), kSc);
  EXPECT_EQ(p(2).rx[1].start, B(77));
  EXPECT_EQ(p(2).rx[1].idle_before, B(11));
  EXPECT_EQ(p(2).rx[2].idle_before, B(40));
  // The requester's own transmission is activity it heard.
  ASSERT_EQ(p(0).rx.size(), 1u);
  EXPECT_EQ(p(0).rx[0].idle_before, B(11));
  ASSERT_EQ(p(1).rx.size(), 2u);
  EXPECT_EQ(p(1).rx[1].idle_before, B(40));
  EXPECT_EQ(rec.gap_bits(1), 11);
  EXPECT_EQ(rec.gap_bits(2), 40);
}

TEST_F(LineTest, IdleIsForeverAgainAfterPowerCycle) {
  make(2);
  line.start();
  p(0).send(B(0), kSd1);
  at(B(100), [&] { line.set_power(1, false); });
  at(B(200), [&] { line.set_power(1, true); });
  p(0).send(B(300), kSd1);
  sched.run_until(B(1000));
  ASSERT_EQ(p(1).rx.size(), 2u);
  EXPECT_EQ(p(1).rx[1].start, B(300));
  EXPECT_EQ(p(1).rx[1].idle_before, kIdleForever);
}

TEST_F(LineTest, ReceiveFilterDeliversOnlyOwnAddressAndBroadcast) {
  Probe master, all;
  Probe slave(5);
  line.attach(master, "master");
  line.attach(slave, "slave 5");
  line.attach(all, "monitor");
  line.start();
  const char* frames[] = {
      "10 05 01 49 4F 16",                               // SD1 to 5
      "10 06 01 49 50 16",                               // SD1 to 6
      "68 05 05 68 85 81 6D 3C 3E ED 16",                // SD2 to 5 with DAE (0x85)
      "E5",                                              // SC: no DA
      "DC 06 01",                                        // token to 6
      "FF 05 05 05",                                     // garbage
      "10 7F 01 44 C4 16",                               // SDN broadcast to 127
      "A2 05 01 08 00 00 00 00 00 00 00 00 0E 16",       // SD3 to 5
      "68 05 05 68 86 81 6D 3C 3E EE 16",                // SD2 to 6
  };
  Ticks t = 0;
  for (const char* f : frames) {
    master.send(t, f);
    t += B(11 * 14 + 50);
  }
  sched.run_until(t + B(1000));
  ASSERT_EQ(all.rx.size(), 9u);
  ASSERT_EQ(slave.rx.size(), 4u);
  EXPECT_EQ(slave.rx[0].hex(), frames[0]);
  EXPECT_EQ(slave.rx[1].hex(), frames[2]);
  EXPECT_EQ(slave.rx[2].hex(), frames[6]);
  EXPECT_EQ(slave.rx[3].hex(), frames[7]);
  // What a filtered station observes is unchanged: its idle counts from the frames it skipped.
  EXPECT_EQ(slave.rx[1].idle_before, all.rx[2].idle_before);
  EXPECT_EQ(slave.rx[1].idle_before, B(11 * 14 + 50 - 6 * 11));
  EXPECT_EQ(slave.rx[3].idle_before, all.rx[7].idle_before);
}

TEST_F(LineTest, ReceiveFilterChangesTakeEffect) {
  Probe master;
  Probe slave(5);
  line.attach(master);
  line.attach(slave);
  line.start();
  // Changed from inside its own callback (like Set_Slave_Add): the line re-reads it.
  slave.on_rx = [&](const bus::RxFrame&) { slave.set_filter(6); };
  master.send(B(0), "10 05 01 49 4F 16");    // to 5: delivered, then the filter becomes 6
  master.send(B(100), "10 05 01 49 4F 16");  // to 5: not any more
  master.send(B(200), "10 06 01 49 50 16");  // to 6: delivered
  sched.run_until(B(300));
  ASSERT_EQ(slave.rx.size(), 2u);
  EXPECT_EQ(slave.rx[1].hex(), "10 06 01 49 50 16");
  // Changed from a timer callback.
  slave.on_rx = nullptr;
  slave.on_tick = [&](Ticks) { slave.set_filter(7); };
  slave.timer(B(310));
  master.send(B(400), "10 07 01 49 51 16");
  sched.run_until(B(500));
  ASSERT_EQ(slave.rx.size(), 3u);
  EXPECT_EQ(slave.rx[2].hex(), "10 07 01 49 51 16");
  // Changed from outside: takes effect once the port is told.
  slave.set_filter(bus::kReceiveAll);
  slave.the_port().receive_filter_changed();
  master.send(B(600), kSc);
  sched.run_until(B(700));
  ASSERT_EQ(slave.rx.size(), 4u);
  EXPECT_EQ(slave.rx[3].hex(), kSc);
  slave.set_filter(9);
  slave.the_port().receive_filter_changed();
  master.send(B(800), kSc);
  master.send(B(900), "10 7F 01 44 C4 16");  // broadcast still reaches a filtered station
  sched.run_until(B(1000));
  ASSERT_EQ(slave.rx.size(), 5u);
  EXPECT_EQ(slave.rx[4].hex(), "10 7F 01 44 C4 16");
}

TEST_F(LineTest, FaultAtTheLastStopBitDoesNotCutAFinishedFrame) {
  make(3);
  line.start();
  p(0).send(0, kSd1);
  // Queued before the frame's end event exists (it is queued when the frame starts), so the cut
  // runs first at B(66), when the last stop bit has just ended.
  at(B(66), [&] { line.set_cut_after(0, true); });
  sched.run_until(B(1000));
  ASSERT_EQ(p(1).rx.size(), 1u);
  EXPECT_EQ(p(1).rx[0].flags, 0);
  EXPECT_EQ(p(1).rx[0].hex(), kSd1);
}

TEST_F(LineTest, FaultAtTheLastStopBitQueuedBeforeTheFrame) {
  make(3);
  line.start();
  // These fault events are queued before the frame's own end event at the same tick.
  at(B(66), [&] { line.set_power(0, false); });
  at(B(66), [&] { line.set_power(2, false); });
  p(0).send(0, kSd1);
  sched.run_until(B(1000));
  ASSERT_EQ(p(1).rx.size(), 1u);
  EXPECT_EQ(p(1).rx[0].flags, 0) << "every character was on the wire before the power went";
  EXPECT_TRUE(p(2).rx.empty()) << "an unpowered receiver gets nothing";
  ASSERT_EQ(rec.size(), 1u);
  EXPECT_EQ(rec.frame(0).flags, 0);
  EXPECT_EQ(line.stats().partial, 0u);
}

TEST_F(LineTest, CollisionGarblesOverlappingCharactersOfBothFrames) {
  make(3);
  line.start();
  const auto sd1 = bytes_from_hex(kSd1);  // [0, 66) bits
  const auto sd2 = bytes_from_hex(kSd2);  // [33, 154) bits: overlaps SD1 characters 3..5
  p(0).send(B(0), sd1);
  p(1).send(B(33), sd2);
  sched.run_until(B(1000));

  ASSERT_EQ(p(2).rx.size(), 2u);
  const auto& a = p(2).rx[0];
  const auto& b = p(2).rx[1];
  EXPECT_EQ(a.flags, bus::kRxCollision);
  EXPECT_EQ(b.flags, bus::kRxCollision);
  ASSERT_EQ(a.bytes.size(), 6u);
  ASSERT_EQ(b.bytes.size(), 11u);
  for (std::size_t i = 0; i < 6; ++i) {
    if (i < 3) EXPECT_EQ(a.bytes[i], sd1[i]) << "SD1 char " << i << " was sent before the overlap";
    else EXPECT_NE(a.bytes[i], sd1[i]) << "SD1 char " << i << " overlapped";
  }
  for (std::size_t i = 0; i < 11; ++i) {
    if (i < 3) EXPECT_NE(b.bytes[i], sd2[i]) << "SD2 char " << i << " overlapped";
    else EXPECT_EQ(b.bytes[i], sd2[i]) << "SD2 char " << i << " was sent after the overlap";
  }
  EXPECT_EQ(b.idle_before, 0) << "the receiver was still hearing SD1";
  EXPECT_EQ(a.idle_before, kIdleForever);
  // The two senders hear each other's damaged frame.
  ASSERT_EQ(p(0).rx.size(), 1u);
  EXPECT_EQ(p(0).rx[0].bytes, b.bytes);
  ASSERT_EQ(p(1).rx.size(), 1u);
  EXPECT_EQ(p(1).rx[0].bytes, a.bytes);
  // Taps see both, damaged, with their senders.
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(0).sender, 0);
  EXPECT_EQ(rec.frame(0).flags, bus::kRxCollision);
  EXPECT_EQ(rec.frame(0).bytes, a.bytes);
  EXPECT_EQ(rec.frame(1).sender, 1);
  EXPECT_EQ(rec.frame(1).flags, bus::kRxCollision);
  EXPECT_EQ(line.stats().collisions, 2u);
}

TEST_F(LineTest, IdleBeforeIsWhatTheReceiverSawWhenTheFrameStarted) {
  make(3);
  line.start();
  p(0).send(B(0), kSd1);    // [0, 66)
  p(0).send(B(100), kSd2);  // [100, 221): 34 idle bits before it
  p(1).send(B(150), kSc);   // [150, 161): inside the SD2, delivered before it ends
  sched.run_until(B(1000));
  ASSERT_EQ(p(2).rx.size(), 3u);
  EXPECT_EQ(p(2).rx[1].hex().size(), 2u);  // the SC (garbled) arrives first
  EXPECT_EQ(p(2).rx[1].idle_before, 0) << "the SD2 was on the line when the SC started";
  EXPECT_EQ(p(2).rx[2].start, B(100));
  EXPECT_EQ(p(2).rx[2].idle_before, B(34)) << "measured before the SD2 started, not at delivery";
  EXPECT_EQ(p(2).rx[2].flags, bus::kRxCollision);
}

TEST_F(LineTest, RepairingACutMakesFramesInFlightOnBothSidesCollide) {
  make(4);
  line.start();
  line.set_cut_after(1, true);
  p(0).send(B(0), kSd2);   // [0, 121) on the left
  p(3).send(B(10), kSd2);  // [10, 131) on the right
  at(B(60), [&] { line.set_cut_after(1, false); });
  sched.run_until(B(1000));
  ASSERT_EQ(p(1).rx.size(), 1u);
  ASSERT_EQ(p(2).rx.size(), 1u);
  const auto sd2 = bytes_from_hex(kSd2);
  // Characters going out from bit 60 on overlap: left frame chars 5.., right frame chars 4..
  EXPECT_EQ(p(1).rx[0].flags, bus::kRxCollision);
  EXPECT_EQ(to_hex(std::span(p(1).rx[0].bytes).first(5)), "68 05 05 68 8A");
  EXPECT_NE(p(1).rx[0].bytes[5], sd2[5]);
  EXPECT_EQ(p(2).rx[0].flags, bus::kRxCollision);
  EXPECT_EQ(to_hex(std::span(p(2).rx[0].bytes).first(4)), "68 05 05 68");
  EXPECT_NE(p(2).rx[0].bytes[4], sd2[4]);
  // Stations that missed the start of a frame from the other side do not receive it.
  EXPECT_EQ(line.stats().collisions, 2u);
}

TEST_F(LineTest, BackToBackFramesDoNotCollide) {
  make(3);
  line.start();
  p(0).send(B(0), kSd1);
  p(1).send(B(66), kSc);  // starts exactly when SD1's last stop bit ends
  sched.run_until(B(1000));
  ASSERT_EQ(p(2).rx.size(), 2u);
  EXPECT_EQ(p(2).rx[0].flags, 0);
  EXPECT_EQ(p(2).rx[1].flags, 0);
  EXPECT_EQ(p(2).rx[1].idle_before, 0);
  EXPECT_EQ(line.stats().collisions, 0u);
}

TEST_F(LineTest, OwnTelegramsAreSentOneAfterTheOther) {
  make(2);
  line.start();
  p(0).send(B(10), kSd1);
  p(0).send(B(10), kToken);
  p(0).send(B(20), kSc);  // asked for while SD1 is still going out
  sched.run_until(B(1000));
  ASSERT_EQ(rec.size(), 3u);
  EXPECT_EQ(rec.hex_all(), (std::vector<std::string>{kSd1, kToken, kSc}));
  EXPECT_EQ(rec.frame(1).start, B(76));
  EXPECT_EQ(rec.frame(2).start, B(76 + 33));
  for (const auto& f : rec.frames()) EXPECT_EQ(f.flags, 0);
  EXPECT_EQ(line.stats().collisions, 0u);
}

TEST_F(LineTest, ReplyFromOnFrameGoesOutAtTheRequestedTime) {
  make(2);
  line.start();
  p(1).on_rx = [&](const bus::RxFrame& f) { p(1).send(f.end + B(11), kSc); };
  p(0).send(0, kSd1);
  sched.run_until(B(1000));
  ASSERT_EQ(p(0).rx.size(), 1u);
  EXPECT_EQ(p(0).rx[0].start, B(77));
  EXPECT_EQ(p(0).rx[0].end, B(88));
  EXPECT_EQ(p(0).rx[0].idle_before, B(11));
}

// --- noise ---------------------------------------------------------------------------------

std::vector<FrameRecorder::Frame> noisy_run(std::uint64_t seed, std::uint64_t ppb) {
  bus::Scheduler s;
  bus::Line l(s, "N", Baud::k1_5M, seed);
  Probe a, b;
  l.attach(a);
  l.attach(b);
  FrameRecorder r;
  l.add_tap(r);
  l.start();
  l.set_noise(ppb);
  for (int i = 0; i < 200; ++i) a.send(i * 200 * 2424, kSd2);
  s.run_until(bus::kTicksPerSecond);
  EXPECT_EQ(b.rx.size(), 200u);
  for (std::size_t i = 0; i < b.rx.size() && i < r.size(); ++i) {
    EXPECT_EQ(b.rx[i].bytes, r.frame(i).bytes);
    EXPECT_EQ(b.rx[i].flags, r.frame(i).flags);
  }
  return r.frames();
}

TEST(LineNoise, SameSeedSameCorruptionOtherSeedOther) {
  const auto x = noisy_run(42, 10'000'000);  // 1 % bit error rate
  const auto y = noisy_run(42, 10'000'000);
  const auto z = noisy_run(43, 10'000'000);
  ASSERT_EQ(x.size(), 200u);
  ASSERT_EQ(y.size(), 200u);
  const auto golden = bytes_from_hex(kSd2);
  int damaged = 0, parity = 0, framing = 0, differs_from_z = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x[i].bytes, y[i].bytes);
    EXPECT_EQ(x[i].flags, y[i].flags);
    if (x[i].flags != 0) ++damaged;
    if (x[i].flags & bus::kRxParity) ++parity;
    if (x[i].flags & bus::kRxFraming) ++framing;
    if (x[i].flags == 0) {
      EXPECT_EQ(x[i].bytes, golden) << "unflagged frame must be intact";
    }
    EXPECT_EQ(x[i].flags & ~(bus::kRxParity | bus::kRxFraming), 0);
    if (x[i].bytes != z[i].bytes || x[i].flags != z[i].flags) ++differs_from_z;
  }
  // 121 bits per frame at 1 %: ~70 % of frames are hit; any sane generator lands well inside.
  EXPECT_GT(damaged, 100);
  EXPECT_LT(damaged, 180);
  EXPECT_GT(parity, 0);
  EXPECT_GT(framing, 0);
  EXPECT_GT(differs_from_z, 50);
}

TEST(LineNoise, NoNoiseNoDamage) {
  for (const auto& f : noisy_run(42, 0)) EXPECT_EQ(f.flags, 0);
}

TEST(LineNoise, EveryBitFlippedInvertsDataAndBreaksParityAndFraming) {
  // All 11 bits of each character flipped: data inverted, start/stop wrong, and the parity bit
  // is inverted while the parity of the inverted data is unchanged.
  for (const auto& f : noisy_run(1, 1'000'000'000)) {
    EXPECT_EQ(to_hex(f.bytes), "97 FA FA 97 75 7E 92 C3 C1 0D E9");
    EXPECT_EQ(f.flags, bus::kRxParity | bus::kRxFraming);
  }
}

// --- partitions and faults -----------------------------------------------------------------

TEST_F(LineTest, CableCutPartitionsTheLineUntilRepaired) {
  make(4);
  line.start();
  at(B(0), [&] { line.set_cut_between(2, 1, true); });
  EXPECT_TRUE(line.connected(0, 3));
  sched.run_until(B(0));
  EXPECT_TRUE(line.cut_after(1));
  EXPECT_TRUE(line.connected(0, 1));
  EXPECT_FALSE(line.connected(1, 2));
  EXPECT_FALSE(line.connected(0, 3));
  EXPECT_TRUE(line.connected(2, 3));
  // Both sides talk at once: separate segments, no collision.
  p(0).send(B(10), kSd1);
  p(3).send(B(10), kSd2);
  at(B(500), [&] { line.set_cut_between(1, 2, false); });
  p(3).send(B(600), kToken);
  sched.run_until(B(1000));

  ASSERT_EQ(p(1).rx.size(), 2u);
  EXPECT_EQ(p(1).rx[0].hex(), kSd1);
  EXPECT_EQ(p(1).rx[0].flags, 0);
  EXPECT_EQ(p(1).rx[1].hex(), kToken);
  ASSERT_EQ(p(2).rx.size(), 2u);
  EXPECT_EQ(p(2).rx[0].hex(), kSd2);
  EXPECT_EQ(p(2).rx[0].flags, 0);
  EXPECT_EQ(p(2).rx[1].hex(), kToken);
  ASSERT_EQ(p(0).rx.size(), 1u);
  EXPECT_EQ(p(0).rx[0].hex(), kToken);
  EXPECT_EQ(rec.size(), 3u);
  EXPECT_EQ(line.stats().collisions, 0u);
  ASSERT_EQ(rec.events().size(), 6u);  // 4 power-on, cut, repair
  EXPECT_EQ(rec.events()[4].kind, LineEventKind::CableCut);
  EXPECT_EQ(rec.events()[4].a, 1);
  EXPECT_EQ(rec.events()[4].b, 2);
  EXPECT_EQ(rec.events()[4].time, 0);
  EXPECT_EQ(rec.events()[5].kind, LineEventKind::CableRepaired);
  EXPECT_EQ(rec.events()[5].time, B(500));
}

TEST_F(LineTest, FrameInFlightArrivesPartialBeyondACut) {
  make(4);
  line.start();
  p(0).send(0, kSd2);  // 11 octets, [0, 121)
  at(B(50), [&] { line.set_cut_after(1, true); });
  sched.run_until(B(1000));

  ASSERT_EQ(p(1).rx.size(), 1u);
  EXPECT_EQ(p(1).rx[0].hex(), kSd2);
  EXPECT_EQ(p(1).rx[0].flags, 0);
  EXPECT_EQ(p(1).rx[0].end, B(121));
  for (int i : {2, 3}) {
    ASSERT_EQ(p(i).rx.size(), 1u);
    EXPECT_EQ(p(i).rx[0].hex(), "68 05 05 68") << "4 whole characters before bit 50";
    EXPECT_EQ(p(i).rx[0].flags, bus::kRxPartial);
    EXPECT_EQ(p(i).rx[0].start, 0);
    EXPECT_EQ(p(i).rx[0].end, B(50));
  }
  // The tap is on the sender's side of the cable: the whole frame.
  ASSERT_EQ(rec.size(), 1u);
  EXPECT_EQ(rec.hex(0), kSd2);
  EXPECT_EQ(rec.frame(0).flags, 0);
  EXPECT_EQ(line.stats().partial, 1u);
}

TEST_F(LineTest, ShortCircuitCutsTheFrameInFlightAndSilencesTheLine) {
  make(3);
  line.start();
  p(0).send(0, kSd2);
  at(B(50), [&] { line.set_short_circuit(true); });
  p(1).send(B(100), kSd1);  // during the short: nobody hears it
  at(B(300), [&] { line.set_short_circuit(false); });
  p(1).send(B(400), kSd1);
  sched.run_until(B(1000));

  for (int i : {1, 2}) {
    ASSERT_GE(p(i).rx.size(), 1u);
    EXPECT_EQ(p(i).rx[0].hex(), "68 05 05 68");
    EXPECT_EQ(p(i).rx[0].flags, bus::kRxPartial);
    EXPECT_EQ(p(i).rx[0].end, B(50));
  }
  ASSERT_EQ(p(1).rx.size(), 1u);
  ASSERT_EQ(p(2).rx.size(), 2u);
  EXPECT_EQ(p(2).rx[1].hex(), kSd1);
  EXPECT_EQ(p(2).rx[1].start, B(400));
  EXPECT_EQ(p(2).rx[1].flags, 0);
  ASSERT_EQ(p(0).rx.size(), 1u);
  EXPECT_EQ(p(0).rx[0].start, B(400));

  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.hex(0), "68 05 05 68");
  EXPECT_EQ(rec.frame(0).flags, bus::kRxPartial);
  EXPECT_EQ(rec.frame(0).end, B(50));
  EXPECT_EQ(rec.frame(0).sent_len, 11u);
  EXPECT_EQ(rec.frame(1).start, B(400));
  EXPECT_EQ(line.stats().lost, 1u);
  EXPECT_EQ(line.stats().partial, 1u);
  EXPECT_TRUE(!line.short_circuit());
}

TEST_F(LineTest, PowerLossDropsPendingWorkAndCutsOwnFrame) {
  make(3);
  line.start();
  p(0).send(0, kSd2);
  p(0).send(B(500), kSd1);  // pending at power loss: dropped
  p(0).timer(B(400));       // armed at power loss: dropped
  at(B(50), [&] { line.set_power(0, false); });
  at(B(60), [&] {
    p(0).send(B(70), kSd1);  // an unpowered device cannot transmit
    p(0).timer(B(80));
  });
  at(B(1000), [&] { line.set_power(0, true); });
  at(B(1100), [&] { p(0).send(B(1100), kToken); });
  sched.run_until(B(2000));

  EXPECT_EQ(p(0).power_offs, std::vector<Ticks>{B(50)});
  EXPECT_EQ(p(0).power_ons, (std::vector<Ticks>{0, B(1000)}));
  EXPECT_TRUE(p(0).timers.empty());
  ASSERT_EQ(p(1).rx.size(), 2u);
  EXPECT_EQ(p(1).rx[0].hex(), "68 05 05 68");
  EXPECT_EQ(p(1).rx[0].flags, bus::kRxPartial);
  EXPECT_EQ(p(1).rx[0].end, B(50));
  EXPECT_EQ(p(1).rx[1].hex(), kToken);
  EXPECT_EQ(p(1).rx[1].start, B(1100));
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.frame(0).flags, bus::kRxPartial);
  EXPECT_EQ(rec.frame(0).bytes.size(), 4u);
  EXPECT_EQ(rec.events()[3].kind, LineEventKind::PowerOff);
  EXPECT_EQ(rec.events()[3].a, 0);
  EXPECT_EQ(rec.events()[4].kind, LineEventKind::PowerOn);
  EXPECT_EQ(rec.events()[4].time, B(1000));
}

TEST_F(LineTest, UnpoweredReceiverHearsNothingNotEvenPartial) {
  make(3);
  line.start();
  p(0).send(0, kSd2);
  at(B(50), [&] { line.set_power(1, false); });
  sched.run_until(B(1000));
  EXPECT_TRUE(p(1).rx.empty());
  ASSERT_EQ(p(2).rx.size(), 1u);
  EXPECT_EQ(p(2).rx[0].flags, 0);
  EXPECT_EQ(p(1).power_offs, std::vector<Ticks>{B(50)});
}

TEST_F(LineTest, FailedTransceiverNeitherDrivesNorHearsButTheDeviceRuns) {
  make(3);
  line.start();
  p(1).send(0, kSd2);
  at(B(50), [&] { line.set_transceiver_ok(1, false); });  // cuts its own frame
  p(0).send(B(200), kSd1);                                 // p1 does not hear it
  p(1).send(B(300), kToken);                               // nobody hears it
  p(1).timer(B(400));                                      // still fires
  bool connected_while_failed = true;
  at(B(450), [&] { connected_while_failed = line.connected(0, 1) || line.connected(1, 2); });
  at(B(500), [&] { line.set_transceiver_ok(1, true); });
  p(0).send(B(600), kSc);
  sched.run_until(B(1000));

  EXPECT_EQ(p(1).timers, std::vector<Ticks>{B(400)});
  ASSERT_EQ(p(1).rx.size(), 1u);
  EXPECT_EQ(p(1).rx[0].hex(), kSc);
  ASSERT_EQ(p(2).rx.size(), 3u);
  EXPECT_EQ(p(2).rx[0].hex(), "68 05 05 68");
  EXPECT_EQ(p(2).rx[0].flags, bus::kRxPartial);
  EXPECT_EQ(p(2).rx[1].hex(), kSd1);
  EXPECT_EQ(p(2).rx[2].hex(), kSc);
  EXPECT_EQ(line.stats().lost, 1u);
  EXPECT_FALSE(connected_while_failed);
  EXPECT_TRUE(line.connected(0, 1));
  EXPECT_EQ(rec.size(), 3u);  // partial SD2, SD1, SC: the lost token never reached the cable
}

TEST_F(LineTest, BabblingTransmitterJamsEveryFrameUntilRepaired) {
  make(3);
  line.start();
  at(B(0), [&] { line.set_babbling(2, true); });
  for (int i = 0; i < 5; ++i) p(0).send(B(100 + 200 * i), kSd1);
  at(B(1050), [&] { line.set_babbling(2, false); });
  p(0).send(B(2000), kSd1);
  sched.run_until(B(3000));

  // Babble: 32-octet bursts back to back from bit 0 until the burst running at bit 1050 ends.
  std::vector<const FrameRecorder::Frame*> babble, mine;
  for (const auto& f : rec.frames()) (f.sender == 2 ? babble : mine).push_back(&f);
  ASSERT_EQ(babble.size(), 3u);  // 352 bits each: [0,352) [352,704) [704,1056)
  for (std::size_t i = 0; i < babble.size(); ++i) {
    EXPECT_EQ(babble[i]->start, B(352 * static_cast<std::int64_t>(i)));
    EXPECT_EQ(babble[i]->bytes.size(), 32u);
    EXPECT_TRUE(babble[i]->flags & bus::kRxBabble);
    EXPECT_TRUE(babble[i]->flags & bus::kRxCollision);
  }
  ASSERT_EQ(mine.size(), 6u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(mine[static_cast<std::size_t>(i)]->flags, bus::kRxCollision) << i;
  EXPECT_EQ(mine[5]->flags, 0);
  EXPECT_EQ(to_hex(mine[5]->bytes), kSd1);
  // The other station receives the babble as (flagged) frames and the jammed requests.
  ASSERT_EQ(p(1).rx.size(), 9u);
  EXPECT_EQ(p(1).rx.back().flags, 0);
  EXPECT_EQ(p(1).rx.back().idle_before, B(2000 - 1056));
  ASSERT_EQ(rec.events().size(), 5u);
  EXPECT_EQ(rec.events()[3].kind, LineEventKind::BabbleOn);
  EXPECT_EQ(rec.events()[3].a, 2);
  EXPECT_EQ(rec.events()[4].kind, LineEventKind::BabbleOff);
}

TEST_F(LineTest, EveryFaultAndRepairReachesTaps) {
  make(3);
  line.start();
  at(B(1), [&] { line.set_cut_after(0, true); });
  at(B(2), [&] { line.set_cut_after(0, false); });
  at(B(3), [&] { line.set_short_circuit(true); });
  at(B(4), [&] { line.set_short_circuit(false); });
  at(B(5), [&] { line.set_noise(1234); });
  at(B(6), [&] { line.set_noise(0); });
  at(B(7), [&] { line.set_power(2, false); });
  at(B(8), [&] { line.set_power(2, true); });
  at(B(9), [&] { line.set_transceiver_ok(1, false); });
  at(B(10), [&] { line.set_transceiver_ok(1, true); });
  at(B(11), [&] { line.set_babbling(1, true); });
  at(B(12), [&] { line.set_babbling(1, false); });
  at(B(13), [&] { line.set_short_circuit(false); });  // no change: no event
  sched.run_until(B(1000));
  const std::vector<LineEventKind> want = {
      LineEventKind::PowerOn,       LineEventKind::PowerOn,           LineEventKind::PowerOn,
      LineEventKind::CableCut,      LineEventKind::CableRepaired,     LineEventKind::ShortCircuit,
      LineEventKind::ShortRepaired, LineEventKind::NoiseOn,           LineEventKind::NoiseOff,
      LineEventKind::PowerOff,      LineEventKind::PowerOn,           LineEventKind::TransceiverFailed,
      LineEventKind::TransceiverRepaired, LineEventKind::BabbleOn,    LineEventKind::BabbleOff};
  ASSERT_EQ(rec.events().size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(rec.events()[i].kind, want[i]) << i;
    EXPECT_EQ(rec.events()[i].line, &line);
    if (i >= 3) {
      EXPECT_EQ(rec.events()[i].time, B(static_cast<std::int64_t>(i) - 2));
    }
  }
  EXPECT_EQ(rec.events()[7].value, 1234u);
  EXPECT_EQ(rec.events()[9].a, 2);
  EXPECT_EQ(rec.events()[11].a, 1);
  EXPECT_EQ(bus::to_string(LineEventKind::CableCut), "cable cut");
}

// --- timers ----------------------------------------------------------------------------------

TEST_F(LineTest, TimerReplaceCancelAndPostpone) {
  make(1);
  line.start();
  Probe& d = p(0);
  d.timer(B(100));
  d.timer(B(50));  // replaces: only 50 fires
  sched.run_until(B(150));
  EXPECT_EQ(d.timers, std::vector<Ticks>{B(50)});

  d.timers.clear();
  d.timer(B(200));
  d.timer(B(300));  // postponed: must not fire at 200
  sched.run_until(B(250));
  EXPECT_TRUE(d.timers.empty());
  sched.run_until(B(350));
  EXPECT_EQ(d.timers, std::vector<Ticks>{B(300)});

  d.timers.clear();
  d.timer(B(400));
  d.timer(bus::kNever);  // cancelled
  sched.run_until(B(500));
  EXPECT_TRUE(d.timers.empty());

  // Re-armed from on_timer; a time in the past fires at once.
  int n = 0;
  d.on_tick = [&](Ticks now) {
    if (++n < 3) d.timer(now + B(10));
  };
  d.timer(B(10));
  sched.run_until(B(600));
  EXPECT_EQ(d.timers, (std::vector<Ticks>{B(500), B(510), B(520)}));

  // Postpone then bring forward again: fires once, at the final deadline.
  d.timers.clear();
  d.on_tick = nullptr;
  d.timer(B(700));
  d.timer(B(900));
  d.timer(B(800));
  sched.run_until(B(1000));
  EXPECT_EQ(d.timers, std::vector<Ticks>{B(800)});
}

// --- determinism ---------------------------------------------------------------------------

std::vector<std::string> busy_scenario(std::uint64_t seed) {
  bus::Scheduler s;
  bus::Line l(s, "D", Baud::k12M, seed);
  std::vector<std::unique_ptr<Probe>> ps;
  for (int i = 0; i < 4; ++i) {
    ps.push_back(std::make_unique<Probe>());
    l.attach(*ps.back());
  }
  FrameRecorder r;
  l.add_tap(r);
  l.start();
  l.set_noise(5'000'000);
  const Ticks bit = 303;
  for (int i = 0; i < 50; ++i) {
    ps[static_cast<std::size_t>(i % 3)]->send(i * 100 * bit, kSd2);
    ps[3]->send(i * 100 * bit + 40 * bit, kSd1);  // overlaps every SD2
  }
  s.schedule(1500 * bit, [&] { l.set_babbling(1, true); });
  s.schedule(2500 * bit, [&] { l.set_babbling(1, false); });
  s.run_until(10'000 * bit);
  std::vector<std::string> out;
  for (const auto& f : r.frames())
    out.push_back(std::to_string(f.start) + " " + std::to_string(f.flags) + " " + to_hex(f.bytes));
  return out;
}

TEST(LineDeterminism, SameSeedSameCapture) {
  const auto a = busy_scenario(9);
  EXPECT_EQ(a, busy_scenario(9));
  EXPECT_NE(a, busy_scenario(10));
  EXPECT_GT(a.size(), 100u);
}

}  // namespace
}  // namespace pbvbus::test
