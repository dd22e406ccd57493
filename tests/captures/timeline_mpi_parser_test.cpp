// The MPI connection rows and the MPI counts of inspect on seeded garbage (also built into the
// ASan+UBSan suite): mutated MPI frames (mpi_frames.hpp MpiMutator) on a marked and an unmarked
// line, whole and in windows. Checked: the model builds, and its invariants hold — spans in
// order, inside the window and of a state, marks in the window and in time order, counts equal
// to the marks.

#include <gtest/gtest.h>

#include <limits>

#include "capture_fixture.hpp"
#include "mpi_frames.hpp"

#include "pbvbus/captures/inspect.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/captures/timeline_render.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

void check_rows(const Timeline& tl) {
  for (const TimelineLane& L : tl.lanes) {
    for (const MpiConnection& c : L.mpi) {
      std::int64_t prev = std::numeric_limits<std::int64_t>::min();
      for (const MpiSpan& s : c.spans) {
        EXPECT_LE(s.start_ns, s.end_ns);
        EXPECT_GE(s.start_ns, prev);
        EXPECT_LT(s.start_ns, tl.to_ns);
        prev = s.end_ns;
      }
      std::uint64_t data = 0, acks = 0;
      std::int64_t t = std::numeric_limits<std::int64_t>::min();
      for (const MpiMark& m : c.marks) {
        EXPECT_GE(m.ts_ns, tl.from_ns);
        EXPECT_LT(m.ts_ns, tl.to_ns);
        EXPECT_GE(m.ts_ns, t);
        t = m.ts_ns;
        data += m.pdu == 0xF1;
        acks += m.pdu == 0xB0;
        EXPECT_FALSE(m.text.empty());
      }
      EXPECT_EQ(c.data_messages, data);
      EXPECT_EQ(c.data_acks, acks);
      EXPECT_GE(c.responder_sap, -1);
      EXPECT_LE(c.responder_sap, 63);
    }
  }
}

TEST(TimelineMpiParser, MutatedFramesKeepTheRowsConsistent) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    bus::Scheduler sched;
    bus::Line mpi(sched, "mpiA", bus::Baud::k187_5);
    bus::Line dp(sched, "dpA", bus::Baud::k187_5);
    test::MemorySink sink;
    {
      PcapngWriter w(sink.sink());
      w.mark_mpi(mpi);
      w.add_line(mpi);
      w.add_line(dp);
      const std::uint32_t s7 = w.add_s7_interface("s7");
      test::MpiMutator mut(seed * 0x9E37'79B9'7F4A'7C15ULL);
      for (int i = 0; i < 300; ++i) {
        // Mostly intact frames, so that connections build up and break down.
        const Bytes b =
            i % 3 ? test::mpi_exchange()[static_cast<std::size_t>(i) % 9] : mut.next_frame();
        w.on_frame(test::tap_frame(i % 5 ? mpi : dp, b, (i + 1) * 200'000));
        if (i % 50 == 0) w.write_s7_pdu(s7, (i + 1) * 200'000, b);  // any octets, not only S7
      }
    }
    std::string error;
    auto whole = build_timeline(sink.data, {}, error);
    ASSERT_TRUE(whole) << error;
    check_rows(*whole);
    EXPECT_FALSE(whole->lanes[0].mpi.empty());
    EXPECT_FALSE(to_svg(*whole).empty());
    EXPECT_FALSE(to_html(*whole).empty());
    TimelineOptions o;
    o.from_ns = whole->first_ns + (whole->last_ns - whole->first_ns) / 3;
    o.to_ns = whole->first_ns + 2 * (whole->last_ns - whole->first_ns) / 3;
    auto part = build_timeline(sink.data, o, error);
    ASSERT_TRUE(part) << error;
    check_rows(*part);
    PcapngReader reader(sink.data);
    PcapngError perr;
    auto s = summarize(reader, perr);
    ASSERT_TRUE(s) << perr.to_string();
    std::uint64_t mpi_pdus = 0;
    for (const auto& [k, n] : s->interfaces[0].by_mpi) mpi_pdus += n;
    EXPECT_GT(mpi_pdus, 0u);
    EXPECT_LE(mpi_pdus, s->interfaces[0].frames);
  }
}

}  // namespace
}  // namespace pbvbus::captures
