// Tests of the shared test helpers (tests/support): they are used by every suite, so a bug
// there would make other tests pass or fail for the wrong reason.

#include <gtest/gtest.h>

#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "recording_port.hpp"

namespace pbvbus::test {
namespace {

using bus::Baud;
using bus::Ticks;

TEST(Hex, RoundTrip) {
  const auto b = bytes_from_hex("68 05 05 68 8a");
  ASSERT_EQ(b.size(), 5u);
  EXPECT_EQ(b[0], 0x68);
  EXPECT_EQ(b[4], 0x8A);
  EXPECT_EQ(to_hex(b), "68 05 05 68 8A");
  EXPECT_EQ(to_hex(bytes_from_hex("10030149")), "10 03 01 49");
  EXPECT_EQ(to_hex({}), "");
  EXPECT_TRUE(bytes_from_hex("").empty());
}

TEST(Hex, RejectsTypos) {
  EXPECT_THROW(bytes_from_hex("6"), std::invalid_argument);
  EXPECT_THROW(bytes_from_hex("6 8"), std::invalid_argument);
  EXPECT_THROW(bytes_from_hex("G0"), std::invalid_argument);
}

/// Answers every frame with its own bytes 11 bit times after the end; sets a timer on power-on.
class Echo final : public bus::Device {
 public:
  void on_power_on(Ticks now) override { port().set_timer(now + 100); }
  void on_frame(const bus::RxFrame& f) override {
    port().transmit(f.end + 11 * bus::ticks_per_bit(port().baud()), f.bytes);
  }
  void on_timer(Ticks now) override { fired_at = now; }
  Ticks fired_at = -1;
};

TEST(RecordingPort, RecordsTransmissionsAndTimer) {
  RecordingPort port(Baud::k12M, 1000);
  Echo dev;
  port.bind(dev);
  EXPECT_FALSE(port.timer_armed());
  dev.on_power_on(port.now());
  EXPECT_EQ(port.timer(), 1100);
  EXPECT_EQ(port.timer_requests(), 1u);

  const auto sd1 = bytes_from_hex("10 03 01 49 4D 16");
  bus::RxFrame f;
  f.bytes = sd1;
  f.start = 1000;
  f.end = 1000 + 66 * 303;
  dev.on_frame(f);
  ASSERT_EQ(port.transmit_count(), 1u);
  EXPECT_EQ(port.last().start, f.end + 11 * 303);
  EXPECT_EQ(port.last().now, 1000);
  EXPECT_EQ(to_hex(port.last_frame()), "10 03 01 49 4D 16");

  EXPECT_FALSE(port.fire_timer_if_due(dev, 1099));
  EXPECT_TRUE(port.fire_timer_if_due(dev, 5000));
  EXPECT_EQ(dev.fired_at, 1100);
  EXPECT_EQ(port.now(), 1100);
  EXPECT_FALSE(port.timer_armed());

  auto first = port.pop_front();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->bytes.size(), 6u);
  EXPECT_FALSE(port.pop_front());
  EXPECT_THROW(port.last(), std::out_of_range);
  port.clear();
  EXPECT_EQ(port.timer_requests(), 0u);
}

class Sender final : public bus::Device {
 public:
  void on_power_on(Ticks) override {}
  void on_frame(const bus::RxFrame&) override {}
  void on_timer(Ticks) override {}
  void send(Ticks at, std::vector<std::uint8_t> b) { port().transmit(at, b); }
};

TEST(FrameRecorder, CopiesFramesAndMeasuresGaps) {
  bus::Scheduler sched;
  bus::Line line(sched, "A", Baud::k1_5M);
  Sender s;
  line.attach(s, "s");
  FrameRecorder rec;
  line.add_tap(rec);
  line.start();
  const Ticks bit = bus::ticks_per_bit(Baud::k1_5M);
  s.send(10 * bit, bytes_from_hex("E5"));
  s.send(10 * bit + 11 * bit + 33 * bit, bytes_from_hex("10 03 01 49 4D 16"));
  line.set_short_circuit(true);
  line.set_short_circuit(false);
  sched.run_until(1000 * bit);
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec.hex(0), "E5");
  EXPECT_EQ(rec.hex(1), "10 03 01 49 4D 16");
  EXPECT_EQ(rec.gap_bits(0), 10);
  EXPECT_EQ(rec.gap_bits(1), 33);
  EXPECT_EQ(rec.start_bits(1), 54);
  EXPECT_EQ(rec.end_bits(1), 54 + 66);
  EXPECT_EQ(rec.frame(1).line, &line);
  EXPECT_EQ(rec.frame(1).sent_len, 6u);
  EXPECT_TRUE(rec.frame(1).intact());
  EXPECT_EQ(rec.hex_all(), (std::vector<std::string>{"E5", "10 03 01 49 4D 16"}));
  ASSERT_EQ(rec.events().size(), 3u);
  EXPECT_EQ(rec.events()[0].kind, bus::LineEventKind::PowerOn);
  EXPECT_EQ(rec.events()[0].a, 0);
  EXPECT_EQ(rec.events()[1].kind, bus::LineEventKind::ShortCircuit);
  EXPECT_EQ(rec.events()[2].kind, bus::LineEventKind::ShortRepaired);
  rec.clear();
  EXPECT_EQ(rec.size(), 0u);
}

}  // namespace
}  // namespace pbvbus::test
