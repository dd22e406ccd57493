// PcapngWriter: exact file bytes against goldens written from the pcapng specification, error
// flags and comments for bad frames, event records, and the round trip through PcapngReader.

#include "pbvbus/captures/pcapng_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "capture_fixture.hpp"

#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

Bytes cat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}
Bytes ascii(std::string_view s) {
  return Bytes(s.begin(), s.end());
}

// SHB: type, total length 44, byte-order magic, version 1.0, section length -1,
// shb_userappl (4) "pbvbus" padded to 8, opt_endofopt, total length.
const Bytes kShb =
    cat({{0x0A, 0x0D, 0x0D, 0x0A, 0x2C, 0x00, 0x00, 0x00, 0x4D, 0x3C, 0x2B, 0x1A, 0x01, 0x00,
          0x00, 0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x04, 0x00, 0x06, 0x00},
         ascii("pbvbus"),
         {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x2C, 0x00, 0x00, 0x00}});

// IDB for line "dp0" at 1.5 Mbit/s: link type 147, reserved, snaplen 0; if_name (2) "dp0" + 1
// pad; if_description (3), 22 octets + 2 pad; if_speed (8) = 1 500 000 = 0x16E360 as u64;
// if_tsresol (9) = 9 + 3 pad; opt_endofopt; total length 80.
const Bytes kIdb = cat(
    {{0x01, 0x00, 0x00, 0x00, 0x50, 0x00, 0x00, 0x00, 0x93, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x02, 0x00, 0x03, 0x00, 'd',  'p',  '0',  0x00, 0x03, 0x00, 0x16, 0x00},
     ascii("PROFIBUS-DP 1.5 Mbit/s"),
     {0x00, 0x00, 0x08, 0x00, 0x08, 0x00, 0x60, 0xE3, 0x16, 0x00, 0x00, 0x00, 0x00, 0x00, 0x09,
      0x00, 0x01, 0x00, 0x09, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x50, 0x00, 0x00, 0x00}});

TEST(PcapngWriter, ExactBytesOfShbIdbAndEpb) {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  test::MemorySink mem;
  {
    PcapngWriter w(mem.sink());
    // 5 s of virtual time = 5 000 000 000 ns = 0x1'2A05'F200: ts_high 1, ts_low 0x2A05F200.
    w.on_frame(test::tap_frame(line, test::kSlaveDiagReq, 5 * bus::kTicksPerSecond));
  }
  // EPB: type 6, length 44, interface 0, ts high, ts low, caplen 11, origlen 11, 11 octets +
  // 1 pad, no options for a good frame, total length.
  const Bytes epb =
      cat({{0x06, 0x00, 0x00, 0x00, 0x2C, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00,
            0x00, 0x00, 0x00, 0xF2, 0x05, 0x2A, 0x0B, 0x00, 0x00, 0x00, 0x0B, 0x00, 0x00, 0x00},
           test::kSlaveDiagReq,
           {0x00, 0x2C, 0x00, 0x00, 0x00}});
  EXPECT_EQ(mem.data, cat({kShb, kIdb, epb}));
}

TEST(PcapngWriter, ExactBytesOfBadFrameWithFlagsAndComment) {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  test::MemorySink mem;
  // FDL Status request with its FCS damaged (4D -> 4E) by a collision.
  const Bytes bad = {0x10, 0x03, 0x01, 0x49, 0x4E, 0x16};
  {
    PcapngWriter w(mem.sink());
    w.add_line(line);
    w.on_frame(test::tap_frame(line, bad, 3636, bus::kRxCollision));  // 1 us = 1000 ns
  }
  // epb_flags (2) = symbol error (bit 24) | CRC error (bit 31) = 0x81000000;
  // opt_comment (1) "collision, FCS mismatch" (23 octets + 1 pad); opt_endofopt; length 80.
  const Bytes epb =
      cat({{0x06, 0x00, 0x00, 0x00, 0x50, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
            0x00, 0x00, 0xE8, 0x03, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00},
           bad,
           {0x00, 0x00, 0x02, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x81, 0x01, 0x00, 0x17, 0x00},
           ascii("collision, FCS mismatch"),
           {0x00, 0x00, 0x00, 0x00, 0x00, 0x50, 0x00, 0x00, 0x00}});
  EXPECT_EQ(mem.data, cat({kShb, kIdb, epb}));
}

TEST(PcapngWriter, LinkType257OnRequest) {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k12M);
  test::MemorySink mem;
  {
    PcapngWriterOptions o;
    o.line_link_type = pcapng::LinkType::ProfibusDl;
    PcapngWriter w(mem.sink(), o);
    w.add_line(line);
  }
  PcapngError err;
  auto cap = read_pcapng(mem.data, err);
  ASSERT_TRUE(cap) << err.to_string();
  ASSERT_EQ(cap->interfaces.size(), 1u);
  EXPECT_EQ(cap->interfaces[0].link_type, 257);
  EXPECT_EQ(cap->interfaces[0].description, "PROFIBUS-DP 12 Mbit/s");
  EXPECT_EQ(cap->interfaces[0].speed, 12'000'000u);
}

TEST(PcapngWriter, ClassifiesBadFrames) {
  std::string c;
  EXPECT_EQ(classify_frame(test::kSlaveDiagReq, 0, 11, c), 0u);
  EXPECT_EQ(c, "");
  // A partial Slave_Diag request: 4 of 11 octets.
  const Bytes partial(test::kSlaveDiagReq.begin(), test::kSlaveDiagReq.begin() + 4);
  EXPECT_EQ(classify_frame(partial, bus::kRxPartial, 11, c), pcapng::kFlagTooShort);
  EXPECT_EQ(c, "partial: 4 of 11 octets");
  // Noise that flipped a parity bit and the FCS.
  Bytes noisy = test::kSlaveDiagReq;
  noisy[5] ^= 0x04;
  EXPECT_EQ(classify_frame(noisy, bus::kRxParity, 11, c), pcapng::kFlagCrcError);
  EXPECT_EQ(c, "parity error, FCS mismatch");
  EXPECT_EQ(classify_frame(Bytes{0x55, 0x55}, bus::kRxBabble, 2, c),
            pcapng::kFlagWrongIfg | pcapng::kFlagStartDelimiterError);
  EXPECT_EQ(c, "babbling transmitter, unknown start delimiter");
  // Intact on the wire but not FDL: SA 127.
  EXPECT_EQ(classify_frame(Bytes{0x10, 0x03, 0x7F, 0x49, 0xCB, 0x16}, 0, 6, c), 0u);
  EXPECT_EQ(c, "source address 127");
  EXPECT_EQ(classify_frame(Bytes{0x10, 0x03, 0x01, 0x49, 0x4D, 0x16, 0x00}, 0, 7, c),
            pcapng::kFlagTooLong);
}

TEST(EventRecord, EncodesTheDocumentedLayout) {
  EventRecord e;
  e.category = EventCategory::Redundancy;
  e.code = 0x0102;
  e.line = 1;
  e.a = 10;
  e.b = -1;
  e.value = 0x73A3;
  e.text = "switchover";
  Bytes out(64);
  ASSERT_EQ(encode_event(e, out), 34u);
  out.resize(34);
  const Bytes golden =
      cat({{0x01, 0x04, 0x02, 0x01, 0x01, 0x00, 0x00, 0x00, 0x0A, 0x00, 0x00, 0x00,
            0xFF, 0xFF, 0xFF, 0xFF, 0xA3, 0x73, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},
           ascii("switchover")});
  EXPECT_EQ(out, golden);
  std::string why;
  auto back = decode_event(out, &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(back->category, EventCategory::Redundancy);
  EXPECT_EQ(back->code, 0x0102);
  EXPECT_EQ(back->line, 1);
  EXPECT_EQ(back->a, 10);
  EXPECT_EQ(back->b, -1);
  EXPECT_EQ(back->value, 0x73A3u);
  EXPECT_EQ(back->text, "switchover");
  EXPECT_FALSE(decode_event(Bytes(out.begin(), out.begin() + 23), &why));
  EXPECT_EQ(why, "event record shorter than its 24-octet header");
  out[0] = 2;
  EXPECT_FALSE(decode_event(out, &why));
  EXPECT_EQ(why, "unsupported event record version");
}

TEST(EventRecord, LongTextIsCutAtACharacterBoundary) {
  EventRecord e;
  e.text = std::string(kEventMaxText - 1, 'x') + "\xC3\xA9";  // 'é' straddles the limit
  Bytes out(kEventHeaderSize + kEventMaxText);
  EXPECT_EQ(encode_event(e, out), kEventHeaderSize + kEventMaxText - 1);
}

TEST(PcapngWriter, LineEventsBecomeRecordsOnTheEventsInterface) {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  line.set_index(2);
  test::IdleDevice m, s1, s2;
  line.attach(m, "master 3");
  line.attach(s1, "slave 10");
  line.attach(s2, "slave 11");
  line.start();
  test::MemorySink mem;
  {
    PcapngWriter w(mem.sink());
    line.add_tap(w);
    w.add_line(line);
    sched.schedule(bus::kTicksPerMs * 2, [&] { line.set_cut_between(0, 1, true); });
    sched.schedule(bus::kTicksPerMs * 3, [&] { line.set_noise(1000); });
    sched.schedule(bus::kTicksPerMs * 4, [&] { line.set_power(2, false); });
    sched.run_until(bus::kTicksPerMs * 10);
    EventRecord note;
    note.category = EventCategory::Station;
    note.code = 1;
    note.a = 10;
    note.text = "slave 10 failed";
    w.write_event(bus::kTicksPerMs * 11, note);
    EXPECT_EQ(w.events_written(), 4u);
    line.remove_tap(w);
  }
  PcapngError err;
  auto cap = read_pcapng(mem.data, err);
  ASSERT_TRUE(cap) << err.to_string();
  ASSERT_EQ(cap->interfaces.size(), 2u);
  EXPECT_EQ(cap->interfaces[1].name, "events");
  EXPECT_EQ(cap->interfaces[1].link_type, 148);
  ASSERT_EQ(cap->records.size(), 4u);
  std::vector<EventRecord> ev;
  for (const auto& r : cap->records) {
    EXPECT_EQ(r.interface, 1u);
    auto e = decode_event(r.bytes);
    ASSERT_TRUE(e);
    ev.push_back(*e);
  }
  EXPECT_EQ(cap->records[0].ts_ns, 2'000'000);
  EXPECT_EQ(ev[0].category, EventCategory::Line);
  EXPECT_EQ(ev[0].code, static_cast<std::uint16_t>(bus::LineEventKind::CableCut));
  EXPECT_EQ(ev[0].line, 2);
  EXPECT_EQ(ev[0].a, 0);
  EXPECT_EQ(ev[0].b, 1);
  EXPECT_EQ(ev[0].text, "dp0: cable cut between 'master 3' and 'slave 10'");
  EXPECT_EQ(ev[1].text, "dp0: noise on: 1000 bit errors per 10^9 bits");
  EXPECT_EQ(ev[1].value, 1000u);
  EXPECT_EQ(ev[2].text, "dp0: power off: 'slave 11'");
  EXPECT_EQ(ev[3].category, EventCategory::Station);
  EXPECT_EQ(ev[3].text, "slave 10 failed");
  EXPECT_EQ(cap->records[3].ts_ns, 11'000'000);
}

TEST(PcapngWriter, RoundTripThroughTheReader) {
  bus::Scheduler sched;
  bus::Line a(sched, "dp0", bus::Baud::k12M);
  bus::Line b(sched, "mpi0", bus::Baud::k187_5);
  test::MemorySink mem;
  const Bytes partial(test::kSetPrm.begin(), test::kSetPrm.begin() + 7);
  {
    PcapngWriter w(mem.sink());
    w.on_frame(test::tap_frame(a, test::kSlaveDiagReq, 1000));
    w.on_frame(test::tap_frame(b, test::kToken_2_to_5, 2000));
    w.on_frame(test::tap_frame(a, test::kSc, 3000));
    w.on_frame(test::tap_frame(a, partial, 4000, bus::kRxPartial, 18));
    EXPECT_EQ(w.frames_written(), 4u);
  }
  PcapngError err;
  auto cap = read_pcapng(mem.data, err);
  ASSERT_TRUE(cap) << err.to_string();
  ASSERT_EQ(cap->interfaces.size(), 2u);
  EXPECT_EQ(cap->interfaces[0].name, "dp0");
  EXPECT_EQ(cap->interfaces[0].speed, 12'000'000u);
  EXPECT_EQ(cap->interfaces[0].tsresol, 9);
  EXPECT_EQ(cap->interfaces[1].name, "mpi0");
  EXPECT_EQ(cap->interfaces[1].description, "PROFIBUS-DP 187.5 kbit/s");
  EXPECT_EQ(cap->interfaces[1].link_type, 147);
  ASSERT_EQ(cap->records.size(), 4u);
  EXPECT_EQ(cap->records[0].bytes, test::kSlaveDiagReq);
  EXPECT_EQ(cap->records[0].ts_ns, bus::ticks_to_ns(1000));
  EXPECT_EQ(cap->records[1].interface, 1u);
  EXPECT_EQ(cap->records[1].bytes, test::kToken_2_to_5);
  EXPECT_EQ(cap->records[2].bytes, test::kSc);
  EXPECT_EQ(cap->records[2].flags, 0u);
  EXPECT_EQ(cap->records[3].bytes, partial);
  EXPECT_EQ(cap->records[3].orig_len, 7u);
  EXPECT_EQ(cap->records[3].flags, pcapng::kFlagTooShort);
  EXPECT_EQ(cap->records[3].comment, "partial: 7 of 18 octets");
}

TEST(PcapngWriter, StreamingFlushesEveryBlock) {
  bus::Scheduler sched;
  bus::Line a(sched, "dp0", bus::Baud::k12M);
  std::vector<std::size_t> writes;
  PcapngWriterOptions o;
  o.streaming = true;
  PcapngWriter w(
      [&](std::span<const std::uint8_t> b) {
        writes.push_back(b.size());
        return true;
      },
      o);
  w.on_frame(test::tap_frame(a, test::kSc, 0));
  // SHB, IDB and EPB each written as soon as they are complete.
  EXPECT_EQ(writes, (std::vector<std::size_t>{44, 80, 36}));
}

TEST(PcapngWriter, DashStreamsToStdoutBlockByBlock) {
  const auto path = std::filesystem::path(test::temp_capture_path("pbvbus_writer_stdout"));
  std::fflush(stdout);
  const int saved = dup(fileno(stdout));
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_TRUE(f);
  dup2(fileno(f), fileno(stdout));
  std::uintmax_t size_while_open = 0;
  {
    auto w = PcapngWriter::open("-", {});
    bus::Scheduler sched;
    bus::Line a(sched, "dp0", bus::Baud::k12M);
    w->on_frame(test::tap_frame(a, test::kSc, 0));
    // Streaming: everything is on its way before the writer is closed.
    size_while_open = std::filesystem::file_size(path);
  }
  std::fflush(stdout);
  dup2(saved, fileno(stdout));
  close(saved);
  std::fclose(f);
  EXPECT_EQ(size_while_open, 44u + 80u + 36u);
  PcapngError err;
  auto cap = read_pcapng_file(path.string(), err);
  ASSERT_TRUE(cap) << err.to_string();
  ASSERT_EQ(cap->records.size(), 1u);
  EXPECT_EQ(cap->records[0].bytes, test::kSc);
  std::filesystem::remove(path);
}

TEST(PcapngWriter, FileSinkAndWriteErrors) {
  const auto path = std::filesystem::path(test::temp_capture_path("pbvbus_writer_test"));
  std::string why;
  {
    auto w = PcapngWriter::open(path.string(), {}, &why);
    ASSERT_TRUE(w) << why;
    bus::Scheduler sched;
    bus::Line a(sched, "dp0", bus::Baud::k12M);
    w->on_frame(test::tap_frame(a, test::kFdlStatusReq, 0));
  }
  PcapngError err;
  auto cap = read_pcapng_file(path.string(), err);
  ASSERT_TRUE(cap) << err.to_string();
  EXPECT_EQ(cap->records.size(), 1u);
  std::filesystem::remove(path);
  EXPECT_FALSE(PcapngWriter::open("/nonexistent-dir/x.pcapng", {}, &why));
  EXPECT_NE(why.find("cannot open '/nonexistent-dir/x.pcapng'"), std::string::npos);

  PcapngWriter failing([](std::span<const std::uint8_t>) { return false; });
  EXPECT_FALSE(failing.flush());
  EXPECT_FALSE(failing.ok());
}

}  // namespace
}  // namespace pbvbus::captures
