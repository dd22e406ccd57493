// Captures taken at probe points (pcapng_writer.hpp): records in start-time order although
// overlapping frames reach the tap by their end, events in time order with them, and one
// interface per probe. Times are chosen in bit times at 1.5 Mbit/s (2424 ticks, 666.67 ns) and
// the expected nanoseconds worked out by hand (rounded down).

#include <gtest/gtest.h>

#include <utility>

#include "capture_fixture.hpp"

#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;
constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks B(std::int64_t bits) { return bits * 2424; }

/// Sends its frames at fixed bit times after power-on.
class Talker final : public bus::Device {
 public:
  explicit Talker(std::vector<std::pair<std::int64_t, Bytes>> plan) : m_plan(std::move(plan)) {}
  void on_power_on(bus::Ticks now) override {
    for (const auto& [bits, bytes] : m_plan)
      port().transmit(now + bus::bits_to_ticks(bits, port().baud()), bytes);
  }
  void on_frame(const bus::RxFrame&) override {}
  void on_timer(bus::Ticks) override {}

 private:
  std::vector<std::pair<std::int64_t, Bytes>> m_plan;
};

struct Read {
  std::vector<PcapngInterface> ifs;
  std::vector<PcapngRecord> recs;
};
Read read_all(const Bytes& data) {
  Read out;
  PcapngReader reader(data);
  PcapngRecord r;
  while (reader.next(r)) out.recs.push_back(r);
  EXPECT_FALSE(reader.error()) << reader.error()->to_string();
  out.ifs = reader.interfaces();
  return out;
}

bus::LineEventKind event_kind(const PcapngRecord& r) {
  auto e = decode_event(r.bytes);
  EXPECT_TRUE(e.has_value());
  return e ? static_cast<bus::LineEventKind>(e->code) : bus::LineEventKind::CableCut;
}

TEST(ProbeCapture, OverlappingFramesAndEventsAreWrittenInStartTimeOrder) {
  bus::Scheduler sched;
  bus::Line line(sched, "A", kBaud);
  // Bit times: the master's Slave_Diag request [300, 421); an SC [330, 341) and a token
  // [360, 393) start inside it (both end first); noise is switched off at 400 while the request
  // is still on the wire; an FDL Status request [500, 566) follows on a quiet line.
  Talker master({{300, test::kSlaveDiagReq}, {500, test::kFdlStatusReq}});
  Talker other({{360, test::kToken_2_to_5}});
  Talker third({{330, test::kSc}});
  line.attach(master, "master 1");
  line.attach(other, "master 2");
  line.attach(third, "slave 10");
  test::MemorySink mem;
  std::vector<std::size_t> held;
  {
    PcapngWriter w(mem.sink());
    EXPECT_EQ(w.add_probe(line, 0), 0u);
    line.add_tap(w, bus::ProbePoint{0});
    line.start();
    sched.schedule(B(400), [&] { line.set_noise(0); });
    for (std::int64_t bits : {345, 395, 402, 430, 600}) {
      sched.run_until(B(bits));
      held.push_back(w.held());
    }
    line.remove_tap(w);
  }
  // Held: the SC from 341, the token from 393, the event at 400. The request itself goes out
  // when it ends at 421 (no earlier start is left); the three after it wait for the next
  // record, the FDL Status request ending at 566 (or a flush).
  EXPECT_EQ(held, (std::vector<std::size_t>{1, 2, 3, 3, 0}));

  const Read r = read_all(mem.data);
  ASSERT_EQ(r.ifs.size(), 2u);
  EXPECT_EQ(r.ifs[0].name, "A");
  EXPECT_EQ(r.ifs[0].description, "PROFIBUS-DP 1.5 Mbit/s, probe at master 1");
  EXPECT_EQ(r.ifs[1].name, "events");
  ASSERT_EQ(r.recs.size(), 8u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(r.recs[i].interface, 1u);
    EXPECT_EQ(r.recs[i].ts_ns, 0);
    EXPECT_EQ(event_kind(r.recs[i]), bus::LineEventKind::PowerOn);
  }
  // 300 bits = 200 000 ns, 330 = 220 000, 360 = 240 000, 400 = 266 666.7, 500 = 333 333.3.
  const std::vector<std::int64_t> ts = {r.recs[3].ts_ns, r.recs[4].ts_ns, r.recs[5].ts_ns,
                                        r.recs[6].ts_ns, r.recs[7].ts_ns};
  EXPECT_EQ(ts, (std::vector<std::int64_t>{200000, 220000, 240000, 266666, 333333}));
  // The request, damaged where the SC and the token overlapped it (octets 2-3 and 5-8).
  EXPECT_EQ(r.recs[3].interface, 0u);
  ASSERT_EQ(r.recs[3].bytes.size(), 11u);
  EXPECT_EQ(r.recs[3].bytes[0], 0x68);
  EXPECT_EQ(r.recs[3].bytes[1], 0x05);
  EXPECT_EQ(r.recs[3].bytes[4], 0x8A);
  EXPECT_NE(r.recs[3].bytes[2], 0x05);
  EXPECT_TRUE(r.recs[3].flags & pcapng::kFlagSymbolError);
  EXPECT_EQ(r.recs[4].bytes.size(), 1u);  // the SC
  EXPECT_NE(r.recs[4].bytes[0], 0xE5);
  EXPECT_TRUE(r.recs[4].flags & pcapng::kFlagSymbolError);
  EXPECT_EQ(r.recs[5].bytes.size(), 3u);  // the token
  EXPECT_TRUE(r.recs[5].flags & pcapng::kFlagSymbolError);
  EXPECT_EQ(r.recs[6].interface, 1u);
  EXPECT_EQ(event_kind(r.recs[6]), bus::LineEventKind::NoiseOff);
  EXPECT_EQ(r.recs[7].bytes, test::kFdlStatusReq);
  EXPECT_EQ(r.recs[7].flags, 0u);
}

TEST(ProbeCapture, FlushWritesWhatIsStillHeld) {
  bus::Scheduler sched;
  bus::Line line(sched, "A", kBaud);
  Talker master({{0, test::kSlaveDiagReq}});  // [0, 121)
  Talker other({{20, test::kSc}});            // [20, 31)
  line.attach(master);
  line.attach(other);
  test::MemorySink mem;
  PcapngWriter w(mem.sink());
  w.add_probe(line, 1);
  line.add_tap(w, bus::ProbePoint{1});
  line.start();
  sched.run_until(B(50));
  EXPECT_EQ(w.held(), 1u);
  EXPECT_TRUE(w.flush());
  EXPECT_EQ(w.held(), 0u);
  const Read r = read_all(mem.data);
  ASSERT_EQ(r.recs.size(), 3u);  // 2 power-on events, the SC
  EXPECT_EQ(r.recs[2].ts_ns, 13333);  // 20 bits
  line.remove_tap(w);
}

TEST(ProbeCapture, SeveralProbesOnALineGetAnInterfaceEach) {
  bus::Scheduler sched;
  bus::Line line(sched, "A", kBaud);
  // master 1, slave 10 | cut after 100 bit times | master 3. At 200 both sides send.
  Talker m1({{200, test::kFdlStatusReq}});  // [200, 266) on the left
  Talker s10({});
  Talker m3({{200, test::kToken_2_to_5}});  // [200, 233) on the right
  line.attach(m1, "master 1");
  line.attach(s10, "slave 10");
  line.attach(m3, "master 3");
  test::MemorySink mem;
  {
    PcapngWriter w(mem.sink());
    EXPECT_EQ(w.add_probe(line, 0, "A@1", "station 1"), 0u);
    EXPECT_EQ(w.add_probe(line, 2, "A@3", "station 3"), 1u);
    EXPECT_EQ(w.add_probe(line, 0, "again", "again"), 0u);
    line.add_tap(w, bus::ProbePoint{0});
    line.add_tap(w, bus::ProbePoint{2});
    line.start();
    sched.schedule(B(100), [&] { line.set_cut_after(1, true); });
    sched.run_until(B(1000));
    line.remove_tap(w);
  }
  const Read r = read_all(mem.data);
  ASSERT_EQ(r.ifs.size(), 3u);
  EXPECT_EQ(r.ifs[0].name, "A@1");
  EXPECT_EQ(r.ifs[0].description, "PROFIBUS-DP 1.5 Mbit/s, probe at station 1");
  EXPECT_EQ(r.ifs[0].speed, 1'500'000u);
  EXPECT_EQ(r.ifs[1].name, "A@3");
  EXPECT_EQ(r.ifs[1].description, "PROFIBUS-DP 1.5 Mbit/s, probe at station 3");
  EXPECT_EQ(r.ifs[2].name, "events");
  // Each event once (the writer sits at two points), then each side's frame on its interface;
  // both start at 200 bits (133 333 ns): equal times go in order of arrival, the token first.
  ASSERT_EQ(r.recs.size(), 6u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(r.recs[i].interface, 2u);
  EXPECT_EQ(event_kind(r.recs[3]), bus::LineEventKind::CableCut);
  EXPECT_EQ(r.recs[3].ts_ns, 66666);
  EXPECT_EQ(r.recs[4].interface, 1u);
  EXPECT_EQ(r.recs[4].bytes, test::kToken_2_to_5);
  EXPECT_EQ(r.recs[4].ts_ns, 133333);
  EXPECT_EQ(r.recs[5].interface, 0u);
  EXPECT_EQ(r.recs[5].bytes, test::kFdlStatusReq);
  EXPECT_EQ(r.recs[5].ts_ns, 133333);
}

TEST(ProbeCapture, UndeclaredProbesAreDeclaredOnTheLinesFirstNews) {
  bus::Scheduler sched;
  bus::Line line(sched, "B", bus::Baud::k187_5);
  Talker m1({});
  Talker m3({});
  line.attach(m1, "master 1");
  line.attach(m3, "master 3");
  test::MemorySink mem;
  {
    PcapngWriter w(mem.sink());
    line.add_tap(w, bus::ProbePoint{0});
    line.add_tap(w, bus::ProbePoint{1});
    line.start();
    line.remove_tap(w);
  }
  const Read r = read_all(mem.data);
  ASSERT_EQ(r.ifs.size(), 3u);
  EXPECT_EQ(r.ifs[0].name, "B@master 1");
  EXPECT_EQ(r.ifs[0].description, "PROFIBUS-DP 187.5 kbit/s, probe at master 1");
  EXPECT_EQ(r.ifs[1].name, "B@master 3");
  EXPECT_EQ(r.ifs[2].name, "events");
  EXPECT_EQ(r.recs.size(), 2u);
}

/// Counts the frames that reach it.
struct CountingTap final : bus::Tap {
  void on_frame(const bus::TapFrame&) override { ++frames; }
  std::uint64_t frames = 0;
};

TEST(ProbeCapture, StartOrderHoldsUnderRandomOverlapsAndFaults) {
  // Five stations send golden frames at pseudo-random times (many overlaps), while cuts,
  // repairs, shorts, a babbling transmitter and power cycles come and go; two probes and a
  // whole-line tap on one writer. Every frame that reaches a tap is written, in start order.
  bus::Scheduler sched;
  bus::Line line(sched, "R", bus::Baud::k12M, 5);
  std::uint64_t x = 12345;
  auto rnd = [&x](std::uint64_t n) {
    x = x * 6364136223846793005ULL + 1442695040888963407ULL;
    return (x >> 33) % n;
  };
  const std::vector<Bytes> golden = {test::kSlaveDiagReq, test::kToken_2_to_5, test::kSc,
                                     test::kFdlStatusReq, test::kSetPrm, test::kDataExchangeRes};
  std::vector<std::unique_ptr<Talker>> talkers;
  for (int i = 0; i < 5; ++i) {
    std::vector<std::pair<std::int64_t, Bytes>> plan;
    for (int k = 0; k < 400; ++k)
      plan.push_back({static_cast<std::int64_t>(rnd(200'000)), golden[rnd(golden.size())]});
    talkers.push_back(std::make_unique<Talker>(std::move(plan)));
    line.attach(*talkers.back(), "t" + std::to_string(i));
  }
  const auto bit = bus::ticks_per_bit(bus::Baud::k12M);
  for (int k = 0; k < 60; ++k) {
    const bus::Ticks t = static_cast<bus::Ticks>(rnd(200'000)) * bit;
    const int what = static_cast<int>(rnd(4));
    const int a = static_cast<int>(rnd(5));
    const bool on = rnd(2) == 0;
    sched.schedule(t, [&line, what, a, on] {
      switch (what) {
        case 0: line.set_cut_after(a < 4 ? a : 3, on); break;
        case 1: line.set_short_circuit(on && a == 0); break;
        case 2: line.set_babbling(a, on && a == 1); break;
        default: line.set_power(a, on || a == 0); break;
      }
    });
  }
  test::MemorySink mem;
  CountingTap at1, at4, whole;
  std::uint64_t written = 0;
  {
    PcapngWriter w(mem.sink());
    w.add_probe(line, 1, "R@1", "t1");
    w.add_probe(line, 4, "R@4", "t4");
    w.add_line(line);
    line.add_tap(w, bus::ProbePoint{1});
    line.add_tap(w, bus::ProbePoint{4});
    line.add_tap(w);
    line.add_tap(at1, bus::ProbePoint{1});
    line.add_tap(at4, bus::ProbePoint{4});
    line.add_tap(whole);
    line.start();
    sched.run_until(250'000 * bit);
    w.flush();
    written = w.frames_written();
    line.remove_tap(w);
  }
  const Read r = read_all(mem.data);
  ASSERT_EQ(r.ifs.size(), 4u);
  std::vector<std::uint64_t> per_if(4, 0);
  std::size_t out_of_order = 0;
  for (std::size_t i = 0; i < r.recs.size(); ++i) {
    ++per_if[r.recs[i].interface];
    if (i > 0 && r.recs[i].ts_ns < r.recs[i - 1].ts_ns) ++out_of_order;
  }
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(per_if[0], at1.frames);
  EXPECT_EQ(per_if[1], at4.frames);
  EXPECT_EQ(per_if[2], whole.frames);
  EXPECT_EQ(per_if[0] + per_if[1] + per_if[2], written);
  EXPECT_GT(at1.frames, 500u);
  EXPECT_GT(line.stats().collisions, 100u);
  EXPECT_NE(at1.frames, at4.frames);  // the cuts kept some frames from one side
}

}  // namespace
}  // namespace pbvbus::captures
