// MPI connections in the timeline (timeline.hpp "MPI connections", captures/README.md "MPI and
// S7") and S7 upper-PDU records in the writer, the reader, inspect and the timeline. Captures
// are written here with the hand-made frames of mpi_frames.hpp at known times; the connection
// rows, their spans and marks are checked exactly, then the window, the rows in the HTML data
// and the SVG, and the exported-PDU record byte for byte.

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "capture_fixture.hpp"
#include "mpi_frames.hpp"

#include "pbvbus/bus/time.hpp"
#include "pbvbus/captures/inspect.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/captures/timeline_render.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

constexpr std::int64_t kMs = 1'000'000;  // ns
constexpr bus::Ticks kSecond = bus::kTicksPerUs * 1'000'000;

/// One capture: line "mpi0" (marked MPI unless `marked` is false) with `frames` at 10 ms,
/// 20 ms, ... and an S7 interface with the §H.4 job and answer at 1 s and 1.001 s.
struct MpiCapture {
  bus::Scheduler sched;
  bus::Line line{sched, "mpi0", bus::Baud::k187_5};
  test::IdleDevice pg, cpu;
  test::MemorySink sink;

  MpiCapture(const std::vector<Bytes>& frames, bool marked = true, bool s7 = true) {
    line.attach(pg, "PG 0");
    line.attach(cpu, "CPU 2");
    PcapngWriter w(sink.sink());
    if (marked) {
      EXPECT_TRUE(w.mark_mpi(line));
    }
    w.add_probe(line, 0);
    EXPECT_FALSE(w.mark_mpi(line));  // declared already: keeps its description
    std::uint32_t s7if = 0;
    if (s7) s7if = w.add_s7_interface("s7door");
    bus::Ticks t = 0;
    for (const Bytes& b : frames) {
      t += 10 * bus::kTicksPerUs * 1000;
      bus::TapFrame f = test::tap_frame(line, b, t);
      f.probe = 0;
      w.on_frame(f);
    }
    if (s7) {
      S7PduInfo in;
      in.direction = S7PduInfo::Direction::Inbound;
      in.src_ip = 0x7F000001;
      in.dst_ip = 0x7F000001;
      in.src_port = 40000;
      in.dst_port = 10102;
      in.comment = "door connection 1";
      EXPECT_TRUE(w.write_s7_pdu(s7if, kSecond, test::kS7ReadJob, in));
      S7PduInfo out;
      out.direction = S7PduInfo::Direction::Outbound;
      EXPECT_TRUE(w.write_s7_pdu(s7if, kSecond + bus::kTicksPerUs * 1000,
                                 test::kS7ReadAnswer, out));
      EXPECT_EQ(w.s7_pdus_written(), 2u);
    }
    EXPECT_TRUE(w.flush());
  }
  Timeline timeline(TimelineOptions o = {}) {
    std::string error;
    auto tl = build_timeline(sink.data, o, error);
    EXPECT_TRUE(tl) << error;
    return tl ? std::move(*tl) : Timeline{};
  }
};

std::vector<std::uint8_t> pdus(const MpiConnection& c) {
  std::vector<std::uint8_t> v;
  for (const MpiMark& m : c.marks) v.push_back(m.pdu);
  return v;
}

TEST(TimelineMpi, OneConnectionFromTheTraceFrames) {
  MpiCapture cap(test::mpi_exchange());
  const Timeline tl = cap.timeline();
  ASSERT_EQ(tl.lanes.size(), 1u);
  EXPECT_EQ(tl.skipped_interfaces, 1u);  // the S7 interface: counted, not drawn
  const TimelineLane& L = tl.lanes[0];
  EXPECT_TRUE(L.mpi_marked);
  EXPECT_EQ(L.description, "MPI 187.5 kbit/s, probe at PG 0");
  ASSERT_EQ(L.mpi.size(), 1u);
  const MpiConnection& c = L.mpi[0];
  EXPECT_EQ(mpi_connection_label(c), "0:20\u21942:20");
  EXPECT_EQ(c.initiator, 0);
  EXPECT_EQ(c.initiator_sap, 0x14);
  EXPECT_EQ(c.responder, 2);
  EXPECT_EQ(c.responder_sap, 0x14);
  EXPECT_TRUE(c.setup_seen);
  // Frames at 10, 20, ... 90 ms: request, confirm, ack PG, ack PLC, job, ack, answer, ack,
  // disconnect.
  ASSERT_EQ(c.spans.size(), 2u);
  EXPECT_EQ(c.spans[0].state, MpiState::Connecting);
  EXPECT_EQ(c.spans[0].start_ns, 10 * kMs);
  EXPECT_EQ(c.spans[0].end_ns, 40 * kMs);  // the PLC's connection ack
  EXPECT_EQ(c.spans[1].state, MpiState::Connected);
  EXPECT_EQ(c.spans[1].start_ns, 40 * kMs);
  EXPECT_EQ(c.spans[1].end_ns, 90 * kMs);  // the disconnect request
  EXPECT_EQ(pdus(c), (std::vector<std::uint8_t>{0xE0, 0xD0, 0x05, 0x05, 0xF1, 0xB0, 0xF1, 0xB0,
                                                0x80}));
  const std::vector<bool> from_pg = {true, false, true, false, true, false, false, true, true};
  for (std::size_t i = 0; i < c.marks.size(); ++i) {
    EXPECT_EQ(c.marks[i].from_initiator, from_pg[i]) << i;
    EXPECT_EQ(c.marks[i].ts_ns, static_cast<std::int64_t>(i + 1) * 10 * kMs) << i;
  }
  EXPECT_EQ(c.marks[4].nr, 0);
  EXPECT_EQ(c.marks[5].nr, 0);
  EXPECT_FALSE(c.marks[0].nr.has_value());
  EXPECT_EQ(c.marks[0].text, "connect request 0:20\u21922:0");
  EXPECT_EQ(c.marks[1].text, "connect confirm 2:20\u21920:20");
  EXPECT_EQ(c.marks[4].text, "data 0 0:20\u21922:20: S7 job Read Var, 1 item");
  EXPECT_EQ(c.marks[5].text, "data ack 0 2:20\u21920:20");
  EXPECT_EQ(c.marks[6].text, "data 0 2:20\u21920:20: S7 ack-data Read Var, 1 item");
  EXPECT_EQ(c.marks[8].text, "disconnect request 0:20\u21922:20");
  EXPECT_EQ(c.data_messages, 2u);
  EXPECT_EQ(c.data_acks, 2u);
  // The frame's own description names its MPI PDU instead of a DP service.
  ASSERT_EQ(L.frames.size(), 9u);
  EXPECT_EQ(L.frames[4].mpi, "data 0");
  const std::string d = describe(L.frames[4]);
  EXPECT_NE(d.find("DSAP 20, SSAP 20 (MPI data 0)\n"), std::string::npos) << d;
  EXPECT_EQ(describe(L.frames[0]).find("MSAC_C2"), std::string::npos);
}

TEST(TimelineMpi, WindowCutsSpansAndMarks) {
  MpiCapture cap(test::mpi_exchange());
  TimelineOptions o;
  o.from_ns = 45 * kMs;
  o.to_ns = 75 * kMs;
  const Timeline tl = cap.timeline(o);
  ASSERT_EQ(tl.lanes.size(), 1u);
  ASSERT_EQ(tl.lanes[0].mpi.size(), 1u);
  const MpiConnection& c = tl.lanes[0].mpi[0];
  ASSERT_EQ(c.spans.size(), 1u);  // connected, 40..90 ms, overlaps the window
  EXPECT_EQ(c.spans[0].state, MpiState::Connected);
  EXPECT_EQ(pdus(c), (std::vector<std::uint8_t>{0xF1, 0xB0, 0xF1}));  // 50, 60, 70 ms
  EXPECT_EQ(c.data_messages, 2u);
  EXPECT_EQ(c.data_acks, 1u);
}

TEST(TimelineMpi, ConnectionSeenFromTheMiddleAndUnconfirmedRequest) {
  // The job, its ack and the answer without the set-up, then a connect request of another PG
  // SAP (0x15) that nothing confirms. Request: 82 80 6D 00 15 E0 + the trace's 11 parameters;
  // FCS = the trace request's 0xED + 1 (SSAP 0x15) = 0xEE.
  const Bytes unconfirmed = {0x68, 0x11, 0x11, 0x68, 0x82, 0x80, 0x6D, 0x00, 0x15, 0xE0, 0x04, 0x00,
                             0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00, 0xEE, 0x16};
  MpiCapture cap({test::kMpiDataJob, test::kMpiDataAckPlc, test::kMpiDataAnswer, unconfirmed});
  const Timeline tl = cap.timeline();
  ASSERT_EQ(tl.lanes[0].mpi.size(), 2u);
  const MpiConnection& c = tl.lanes[0].mpi[0];
  EXPECT_EQ(mpi_connection_label(c), "0:20\u21942:20");
  EXPECT_FALSE(c.setup_seen);  // initiator = the sender of the first PDU seen
  ASSERT_EQ(c.spans.size(), 1u);
  EXPECT_EQ(c.spans[0].state, MpiState::Connected);
  EXPECT_EQ(c.spans[0].start_ns, 10 * kMs);
  // To the lane's end: the last frame (23 octets at 187.5 kbit/s: 253 bit times = 1349333 ns)
  EXPECT_EQ(c.spans[0].end_ns, 40 * kMs + 1'349'333);
  EXPECT_EQ(pdus(c), (std::vector<std::uint8_t>{0xF1, 0xB0, 0xF1}));
  const MpiConnection& u = tl.lanes[0].mpi[1];
  EXPECT_EQ(mpi_connection_label(u), "0:21\u21942:?");
  EXPECT_EQ(u.responder_sap, -1);
  EXPECT_TRUE(u.spans.empty());
  EXPECT_EQ(pdus(u), (std::vector<std::uint8_t>{0xE0}));
}

TEST(TimelineMpi, DpSapsAreMpiOnlyOnAMarkedLane) {
  // The same frames: the high-SAP data message and DP frames with SAPs.
  const std::vector<Bytes> frames = {test::kMpiDataHighSap, test::kSetPrm, test::kDpv1Read,
                                     test::kSlaveDiagReq, test::kChkCfg};
  {
    MpiCapture cap(frames, /*marked=*/true, /*s7=*/false);
    const Timeline tl = cap.timeline();
    ASSERT_EQ(tl.lanes[0].mpi.size(), 1u);
    EXPECT_EQ(mpi_connection_label(tl.lanes[0].mpi[0]), "0:20\u21942:50");
  }
  {
    MpiCapture cap(frames, /*marked=*/false, /*s7=*/false);
    const Timeline tl = cap.timeline();
    EXPECT_FALSE(tl.lanes[0].mpi_marked);
    EXPECT_EQ(tl.lanes[0].description, "PROFIBUS-DP 187.5 kbit/s, probe at PG 0");
    EXPECT_TRUE(tl.lanes[0].mpi.empty());
  }
  {
    // Unmarked, but both SAPs below 49: MPI by the SAP rule.
    MpiCapture cap(test::mpi_exchange(), /*marked=*/false, /*s7=*/false);
    const Timeline tl = cap.timeline();
    ASSERT_EQ(tl.lanes[0].mpi.size(), 1u);
    EXPECT_EQ(tl.lanes[0].mpi[0].marks.size(), 9u);
  }
}

TEST(TimelineMpi, RowsInTheSvgAndTheHtmlData) {
  MpiCapture cap(test::mpi_exchange());
  const Timeline tl = cap.timeline();
  const std::string svg = to_svg(tl);
  EXPECT_NE(svg.find("<g class=\"mpi-conn\" data-conn=\"0:20\u21942:20\">"), std::string::npos);
  EXPECT_NE(svg.find("class=\"mpi-span\" data-state=\"connecting\""), std::string::npos);
  EXPECT_NE(svg.find("class=\"mpi-span\" data-state=\"connected\""), std::string::npos);
  std::size_t marks = 0;
  for (std::size_t p = svg.find("class=\"mpi-mark\""); p != std::string::npos;
       p = svg.find("class=\"mpi-mark\"", p + 1))
    ++marks;
  EXPECT_EQ(marks, 9u);
  EXPECT_NE(svg.find(">MPI 0:20\u21942:20</text>"), std::string::npos);
  EXPECT_NE(svg.find("MPI 0:20\u21942:20: 2 data messages, 2 data acks"), std::string::npos);
  const std::string html = to_html(tl);
  EXPECT_NE(html.find("\"mpi\":[{\"l\":\"0:20\u21942:20\",\"s\":[["), std::string::npos);
  EXPECT_NE(html.find("data 0 0:20\u21922:20: S7 job Read Var, 1 item"), std::string::npos);
}

TEST(S7UpperPdu, RecordBytesTagsAndFlags) {
  MpiCapture cap({test::kMpiConnectRequest});
  PcapngError err;
  auto c = read_pcapng(cap.sink.data, err);
  ASSERT_TRUE(c) << err.to_string();
  ASSERT_EQ(c->interfaces.size(), 2u);
  EXPECT_EQ(c->interfaces[1].link_type, 252);
  EXPECT_EQ(c->interfaces[1].name, "s7door");
  EXPECT_EQ(c->interfaces[1].description, "S7 PDUs (exported PDU for s7comm)");
  ASSERT_EQ(c->records.size(), 3u);
  const PcapngRecord& job = c->records[1];
  EXPECT_EQ(job.interface, 1u);
  EXPECT_EQ(job.ts_ns, 1'000'000'000);
  EXPECT_EQ(job.flags, 1u);  // inbound
  EXPECT_EQ(job.comment, "door connection 1");
  // Tag 13 "s7comm_cotp" NUL (12 octets), IPv4 source and destination 127.0.0.1, port type
  // TCP (2), ports 40000 (0x9C40) and 10102 (0x2776), end tag, then the PDU.
  Bytes want = {0x00, 0x0D, 0x00, 0x0C, 's', '7', 'c', 'o', 'm', 'm', '_', 'c', 'o', 't', 'p', 0x00,
          0x00, 0x14, 0x00, 0x04, 0x7F, 0x00, 0x00, 0x01, 0x00, 0x15, 0x00, 0x04, 0x7F, 0x00,
          0x00, 0x01, 0x00, 0x18, 0x00, 0x04, 0x00, 0x00, 0x00, 0x02, 0x00, 0x19, 0x00, 0x04,
          0x00, 0x00, 0x9C, 0x40, 0x00, 0x1A, 0x00, 0x04, 0x00, 0x00, 0x27, 0x76, 0x00, 0x00,
          0x00, 0x00};
  want.insert(want.end(), test::kS7ReadJob.begin(), test::kS7ReadJob.end());
  EXPECT_EQ(job.bytes, want);
  const PcapngRecord& answer = c->records[2];
  EXPECT_EQ(answer.flags, 2u);  // outbound
  Bytes want2 = {0x00, 0x0D, 0x00, 0x0C, 's', '7', 'c', 'o', 'm', 'm', '_',
                 'c',  'o',  't',  'p',  0x00, 0x00, 0x00, 0x00, 0x00};
  want2.insert(want2.end(), test::kS7ReadAnswer.begin(), test::kS7ReadAnswer.end());
  EXPECT_EQ(answer.bytes, want2);
}

TEST(S7UpperPdu, InspectCountsTheRecords) {
  MpiCapture cap(test::mpi_exchange());
  PcapngReader reader(cap.sink.data);
  PcapngError err;
  auto s = summarize(reader, err);
  ASSERT_TRUE(s) << err.to_string();
  ASSERT_EQ(s->interfaces.size(), 2u);
  EXPECT_EQ(s->interfaces[0].frames, 9u);
  EXPECT_TRUE(s->interfaces[0].by_service.empty());  // no MSAC_C2 for the SAPs 0 and 20
  EXPECT_EQ(s->interfaces[0].by_mpi,
            (std::map<std::string, std::uint64_t>{{"Connect confirm", 1},
                                                  {"Connect request", 1},
                                                  {"Connection ack", 2},
                                                  {"Data", 2},
                                                  {"Data ack", 2},
                                                  {"Disconnect request", 1}}));
  EXPECT_EQ(s->interfaces[1].link_type, 252);
  EXPECT_EQ(s->interfaces[1].frames, 2u);
  const std::string text = to_text(*s);
  EXPECT_NE(text.find("Interface 1 's7door' (UPPER_PDU, speed unknown): 2 records"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  MPI PDUs: Connect confirm 1, Connect request 1, Connection ack 2, Data 2, "
                      "Data ack 2, Disconnect request 1\n"),
            std::string::npos)
      << text;
  EXPECT_NE(to_json(*s).find("\"link_type\":252"), std::string::npos);
  EXPECT_NE(to_json(*s).find("\"mpi_pdus\":{\"Connect confirm\":1,"), std::string::npos);
}

TEST(S7UpperPdu, OnlyOnS7Interfaces) {
  test::MemorySink sink;
  PcapngWriter w(sink.sink());
  const std::uint32_t ev = w.events_interface();
  EXPECT_FALSE(w.write_s7_pdu(ev, 0, test::kS7ReadJob));
  const std::uint32_t s7 = w.add_s7_interface("s7", "door 10102");
  EXPECT_TRUE(w.write_s7_pdu(s7, 0, test::kS7ReadJob));
  EXPECT_EQ(w.s7_pdus_written(), 1u);
}

}  // namespace
}  // namespace pbvbus::captures
