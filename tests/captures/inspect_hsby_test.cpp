// `pbvbus inspect` on a capture with a Quantum Hot Standby pair's records (inspect.hpp,
// hsby_event.hpp): the Hsby records counted apart, the switchovers listed with their takeover
// times, in text and JSON; a capture without them shows no Quantum part in the text.

#include <gtest/gtest.h>

#include "capture_fixture.hpp"

#include "pbvbus/captures/hsby_event.hpp"
#include "pbvbus/captures/inspect.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

EventRecord insp_hs(HsbyEventKind kind, int rack, int state, std::string text, std::uint64_t takeover = 0) {
  HsbyEventFields f;
  f.kind = kind;
  f.rack = rack;
  f.state = state;
  f.takeover_ns = takeover;
  f.text = std::move(text);
  return hsby_event_record(f);
}

Bytes make_inspect_hsby_capture() {
  test::MemorySink mem;
  PcapngWriter w(mem.sink());
  w.add_interface("DP_A", "PROFIBUS-DP 1.5 Mbit/s", pcapng::LinkType::User0, 1'500'000);
  using K = HsbyEventKind;
  w.write_event(1 * bus::kTicksPerMs, insp_hs(K::State, 0, 2, "Q: rack 0: offline -> primary"));
  w.write_event(2 * bus::kTicksPerMs, insp_hs(K::State, 1, 3, "Q: rack 1: offline -> standby"));
  // 37 ms + 250 µs + 7 ns = 37 250 007 ns: the text shows it to the µs, rounded down.
  w.write_event(40 * bus::kTicksPerMs, insp_hs(K::Switchover, 1, 2, "Q: rack 1: switchover", 37'250'007));
  w.write_event(50 * bus::kTicksPerMs, insp_hs(K::Switchover, 0, 2, "Q: rack 0: two primaries"));
  EventRecord note;
  note.category = EventCategory::Note;
  note.text = "Q: power off rack 0";
  w.write_event(60 * bus::kTicksPerMs, note);
  w.flush();
  return mem.data;
}

TEST(InspectHsby, CountsAndSwitchovers) {
  PcapngReader reader(make_inspect_hsby_capture());
  PcapngError err;
  const auto s = summarize(reader, err);
  ASSERT_TRUE(s) << err.to_string();
  EXPECT_EQ(s->events.size(), 5u);
  EXPECT_EQ(s->hsby_records, 4u);
  ASSERT_EQ(s->hsby_switchovers.size(), 2u);
  EXPECT_EQ(s->hsby_switchovers[0].ts_ns, 40'000'000);
  EXPECT_EQ(s->hsby_switchovers[0].rack, 1);
  EXPECT_EQ(s->hsby_switchovers[0].takeover_ns, 37'250'007u);
  const std::string text = to_text(*s);
  EXPECT_NE(text.find("  0.040000000 s  [hsby] Q: rack 1: switchover\n"), std::string::npos) << text;
  EXPECT_NE(text.find("Quantum Hot Standby: 4 records, 2 switchovers\n"
                      "  0.040000000 s  to rack 1, takeover 37.250 ms: Q: rack 1: switchover\n"
                      "  0.050000000 s  to rack 0, no takeover time: Q: rack 0: two primaries\n"),
            std::string::npos)
      << text;
  const std::string j = to_json(*s);
  EXPECT_NE(j.find("\"hsby\":{\"records\":4,\"switchovers\":[{\"ts_ns\":40000000,\"rack\":1,"
                   "\"takeover_ns\":37250007,\"text\":\"Q: rack 1: switchover\"},{\"ts_ns\":50000000,"
                   "\"rack\":0,\"takeover_ns\":0,\"text\":\"Q: rack 0: two primaries\"}]},\"events\":["),
            std::string::npos)
      << j;
}

TEST(InspectHsby, NoPairNoQuantumPart) {
  test::MemorySink mem;
  PcapngWriter w(mem.sink());
  w.add_interface("DP_A", "PROFIBUS-DP 1.5 Mbit/s", pcapng::LinkType::User0, 1'500'000);
  EventRecord note;
  note.category = EventCategory::Note;
  note.text = "nothing";
  w.write_event(1, note);
  w.flush();
  PcapngReader reader(mem.data);
  PcapngError err;
  const auto s = summarize(reader, err);
  ASSERT_TRUE(s);
  EXPECT_EQ(to_text(*s).find("Quantum"), std::string::npos);
  EXPECT_NE(to_json(*s).find("\"hsby\":{\"records\":0,\"switchovers\":[]}"), std::string::npos);
}

}  // namespace
}  // namespace pbvbus::captures
