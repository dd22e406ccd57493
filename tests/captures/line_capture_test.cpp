// A capture taken from a real line: stations transmit at chosen bit times, a station loses power
// in the middle of its frame; the writer (a tap) records it and inspect reads the timing back in
// bit times.

#include <gtest/gtest.h>

#include <utility>

#include "capture_fixture.hpp"

#include "pbvbus/captures/inspect.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

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

TEST(LineCapture, TimingAndFaultsFromARealLine) {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k12M);
  // Bit times: request 0..121 (11 octets), reply after TSDR 11 at 132..286, token after 33
  // idle bits at 319..352, Data_Exchange after 40 at 392..513, its reply after 15 at 528.
  Talker master(
      {{100, test::kSlaveDiagReq}, {419, test::kToken_2_to_5}, {492, test::kDataExchange}});
  Talker slave({{232, test::kSlaveDiagRes}, {628, test::kDataExchangeRes}});
  line.attach(master, "master 1");
  line.attach(slave, "slave 10");
  test::MemorySink mem;
  {
    PcapngWriter w(mem.sink());
    line.add_tap(w);
    line.start();
    // The slave loses power 50 bit times into its Data_Exchange reply: 4 whole characters out.
    sched.schedule(bus::bits_to_ticks(628 + 50, bus::Baud::k12M),
                   [&] { line.set_power(1, false); });
    sched.run_until(bus::bits_to_ticks(2000, bus::Baud::k12M));
    line.remove_tap(w);
  }
  PcapngReader reader(mem.data);
  PcapngRecord r;
  std::vector<PcapngRecord> recs;
  while (reader.next(r)) recs.push_back(r);
  ASSERT_FALSE(reader.error()) << reader.error()->to_string();
  ASSERT_EQ(recs.size(), 8u);        // 2 power-on events, 5 frames, the power-off event
  EXPECT_EQ(recs[0].interface, 1u);  // events; the line keeps interface 0
  EXPECT_EQ(recs[2].bytes, test::kSlaveDiagReq);
  EXPECT_EQ(recs[2].ts_ns, 8333);   // 100 bits at 12 Mbit/s = 8333.3 ns
  EXPECT_EQ(recs[3].ts_ns, 19333);  // 232 bits = 19333.3 ns
  std::optional<std::size_t> partial;
  for (std::size_t i = 0; i < recs.size(); ++i)
    if (recs[i].flags == pcapng::kFlagTooShort) partial = i;
  ASSERT_TRUE(partial);
  EXPECT_EQ(recs[*partial].bytes,
            Bytes(test::kDataExchangeRes.begin(), test::kDataExchangeRes.begin() + 4));
  EXPECT_EQ(recs[*partial].comment, "partial: 4 of 10 octets");

  PcapngReader again(mem.data);
  PcapngError err;
  auto s = summarize(again, err);
  ASSERT_TRUE(s) << err.to_string();
  ASSERT_EQ(s->interfaces.size(), 2u);
  EXPECT_EQ(s->interfaces[1].name, "events");
  const InterfaceSummary& dp0 = s->interfaces[0];
  EXPECT_EQ(dp0.frames, 5u);
  EXPECT_EQ(dp0.min_idle_bits, 11);
  EXPECT_EQ(dp0.overlaps, 0u);
  EXPECT_EQ(dp0.bad_frames, 1u);
  EXPECT_EQ(dp0.bad_by_reason, (std::map<std::string, std::uint64_t>{{"partial", 1}}));
  ASSERT_EQ(s->events.size(), 3u);
  EXPECT_EQ(s->events[0].text, "dp0: power on: 'master 1'");
  EXPECT_EQ(s->events[0].ts_ns, 0);
  EXPECT_EQ(s->events[2].text, "dp0: power off: 'slave 10'");
  EXPECT_EQ(s->events[2].ts_ns, 56500);  // 678 bits = 56500 ns
}

}  // namespace
}  // namespace pbvbus::captures
