// `pbvbus inspect`: a capture written with PcapngWriter from golden frames (protocol-facts.md
// Appendix 1, written here by hand) laid out in bit times at 500 kbit/s (1 bit = 2 us, so every
// timestamp is exact in ns) gives the expected summary; broken files give exit 2 and the offset.

#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {
namespace {

using Bytes = std::vector<std::uint8_t>;

// protocol-facts.md Appendix 1
const Bytes kFdlStatusReq = {0x10, 0x03, 0x01, 0x49, 0x4D, 0x16};
const Bytes kSc = {0xE5};
const Bytes kToken_2_to_5 = {0xDC, 0x05, 0x02};
const Bytes kSlaveDiagReq = {0x68, 0x05, 0x05, 0x68, 0x8A, 0x81, 0x6D, 0x3C, 0x3E, 0xF2, 0x16};
const Bytes kSlaveDiagRes = {0xA2, 0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x02, 0x05,
                             0x00, 0xFF, 0x12, 0x34, 0xD9, 0x16};

std::string temp_path(const std::string& stem) {
  return (std::filesystem::temp_directory_path() / (stem + "_" + std::to_string(::getpid()) + ".pcapng"))
      .string();
}

bus::TapFrame tap_frame(const bus::Line& line, const Bytes& bytes, bus::Ticks start) {
  bus::TapFrame f;
  f.line = &line;
  f.bytes = bytes;
  f.start = start;
  f.end = start + static_cast<bus::Ticks>(bytes.size()) * 11 * bus::ticks_per_bit(line.baud());
  f.sent_len = static_cast<std::uint32_t>(bytes.size());
  return f;
}

Bytes make_capture() {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k500);
  Bytes data;
  captures::PcapngWriter w([&](std::span<const std::uint8_t> b) {
    data.insert(data.end(), b.begin(), b.end());
    return true;
  });
  const bus::Ticks bit = bus::ticks_per_bit(bus::Baud::k500);
  bus::Ticks t = bus::kTicksPerMs;
  auto put = [&](const Bytes& b, bus::Ticks idle_bits) {
    t += idle_bits * bit;
    w.on_frame(tap_frame(line, b, t));
    t += static_cast<bus::Ticks>(b.size()) * 11 * bit;
  };
  put(kFdlStatusReq, 0);   // bit 0
  put(kSc, 11);            // bit 66 + 11 = 77
  put(kToken_2_to_5, 40);  // bit 88 + 40 = 128
  put(kSlaveDiagReq, 33);  // bit 161 + 33 = 194
  put(kSlaveDiagRes, 11);  // bit 315 + 11 = 326 -> 652 us
  captures::EventRecord e;
  e.category = captures::EventCategory::Station;
  e.a = 5;
  e.text = "slave 5 failed";
  w.write_event(2 * bus::kTicksPerMs, e);
  w.flush();
  return data;
}

void write_file(const std::string& path, const Bytes& data) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
}

struct Result {
  int rc;
  std::string out;
  std::string err;
};

Result run(const Args& args) {
  std::ostringstream out, err;
  const int rc = cmd_inspect(args, out, err);
  return {rc, out.str(), err.str()};
}

class CmdInspect : public ::testing::Test {
 protected:
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove(m_path, ec);
  }
  std::string m_path = temp_path("cmd_inspect");
};

TEST_F(CmdInspect, TextSummary) {
  write_file(m_path, make_capture());
  const Result r = run({m_path});
  EXPECT_EQ(r.rc, 0) << r.err;
  // 6 + 1 + 3 + 11 + 14 = 35 octets; the event record is 24 octets + 14 of text.
  const std::string expected =
      "Records: 6 (1 events)\n"
      "Time span: 0.001000000 s .. 0.002000000 s (0.001000000 s)\n"
      "Interface 0 'dp0' (USER0, 500 kbit/s): 5 records, 35 octets\n"
      "  time span: 0.001000000 s .. 0.001652000 s\n"
      "  frame types: SC 1, SD1 1, SD2 1, SD3 1, SD4 1\n"
      "  requests: FDL_Status 1, SRD_high 1\n"
      "  responses: DL 1\n"
      "  DP services: Slave_Diag.req 1, Slave_Diag.res 1\n"
      "  bad frames: 0\n"
      "  min idle gap: 11 bit times\n"
      "Interface 1 'events' (USER1, speed unknown): 1 records, 38 octets\n"
      "  time span: 0.002000000 s .. 0.002000000 s\n"
      "Events: 1\n"
      "  0.002000000 s  [station] slave 5 failed\n";
  EXPECT_EQ(r.out, expected);
  EXPECT_EQ(r.err, "");
}

TEST_F(CmdInspect, JsonParses) {
  write_file(m_path, make_capture());
  const Result r = run({m_path, "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out.rfind("{\"records\":6,\"first_ns\":1000000,\"last_ns\":2000000,", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("\"min_idle_bits\":11"), std::string::npos);
  const std::string json_path = temp_path("cmd_inspect_json");
  {
    std::ofstream f(json_path);
    f << r.out;
  }
  const std::string cmd = "python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); "
                          "print(d[\"interfaces\"][0][\"frame_types\"][\"SD3\"], d[\"events\"][0][\"text\"])' " +
                          json_path;
  std::unique_ptr<FILE, int (*)(FILE*)> p(::popen(cmd.c_str(), "r"), ::pclose);
  ASSERT_TRUE(p);
  std::array<char, 256> buf{};
  std::string got;
  while (std::fgets(buf.data(), buf.size(), p.get())) got += buf.data();
  const int status = ::pclose(p.release());
  std::filesystem::remove(json_path);
  EXPECT_EQ(status, 0);
  EXPECT_EQ(got, "1 slave 5 failed\n");
}

TEST_F(CmdInspect, GarbageFileIsExit2WithOffset) {
  write_file(m_path, Bytes{'n', 'o', 't', ' ', 'a', ' ', 'c', 'a', 'p', 't', 'u', 'r', 'e', '!', '\n', 0});
  const Result r = run({m_path});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err.rfind("pbvbus inspect: " + m_path + ": offset 0: ", 0), 0u) << r.err;
}

TEST_F(CmdInspect, TruncatedFileNamesTheBrokenBlock) {
  Bytes data = make_capture();
  // Cut the file in the middle of the last block (the event's EPB).
  data.resize(data.size() - 10);
  write_file(m_path, data);
  const Result r = run({m_path});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find(": offset "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(": offset 0:"), std::string::npos) << r.err;
}

TEST_F(CmdInspect, EmptyAndMissingFiles) {
  write_file(m_path, Bytes{});
  Result r = run({m_path});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus inspect: " + m_path + ": offset 0: empty file, not a pcapng capture\n");
  r = run({m_path + ".does-not-exist"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("cannot open"), std::string::npos) << r.err;
}

TEST_F(CmdInspect, Usage) {
  Result r = run({"--help"});
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(r.out.rfind("usage: pbvbus inspect CAPTURE [--json]\n", 0), 0u);
  r = run({});
  EXPECT_EQ(r.rc, 2);
  r = run({"--bogus", m_path});
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("'--bogus'"), std::string::npos);
  r = run({"a.pcapng", "b.pcapng"});
  EXPECT_EQ(r.rc, 2);
}

}  // namespace
}  // namespace pbvbus::tools
