// MPI and S7 in a capture as Debian's tshark sees it (captures/README.md "MPI and S7"): the
// shipped Lua dissector decodes the MPI connection layer of the docs/mpi.md frames and hands
// the S7 PDUs of data messages to tshark's own s7comm; S7 PDUs written as upper-PDU records
// (link type 252) decode with s7comm with or without the script. All frames and PDUs are
// written by hand (mpi_frames.hpp); the writer only stores them.

#include <gtest/gtest.h>

#include <filesystem>

#include "capture_fixture.hpp"
#include "mpi_frames.hpp"
#include "tshark_helpers.hpp"

#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;
namespace ts = ::pbvbus::test;
using R = std::vector<std::string>;

class TsharkMpi : public ::testing::Test {
 protected:
  // Interfaces: 0 "mpi0" (marked MPI, probe at the PG), 1 "dp0" (not marked), 2 "s7door".
  // Packets: 1..10 on mpi0 (the exchange, then the high-SAP data message), 11..15 on dp0 (the
  // connect request, the job, two DP frames with SAPs, the high-SAP data message), 16 and 17 the
  // S7 job and answer on s7door.
  static void SetUpTestSuite() {
    s_path = test::temp_capture_path("pbvbus_tshark_mpi_test");
    bus::Scheduler sched;
    bus::Line mpi(sched, "mpi0", bus::Baud::k187_5);
    bus::Line dp(sched, "dp0", bus::Baud::k1_5M);
    test::IdleDevice pg, cpu, m, s;
    mpi.attach(pg, "PG 0");
    mpi.attach(cpu, "CPU 2");
    dp.attach(m, "master 1");
    dp.attach(s, "slave 10");
    std::string why;
    auto w = PcapngWriter::open(s_path, {}, &why);
    ASSERT_TRUE(w) << why;
    ASSERT_TRUE(w->mark_mpi(mpi));
    w->add_probe(mpi, 0);
    w->add_probe(dp, 0);
    const std::uint32_t s7 = w->add_s7_interface("s7door");
    const bus::Ticks ms = bus::kTicksPerUs * 1000;
    bus::Ticks t = 0;
    auto put = [&](const bus::Line& line, const Bytes& b) {
      t += ms;
      bus::TapFrame f = test::tap_frame(line, b, t);
      f.probe = 0;
      w->on_frame(f);
    };
    for (const Bytes& b : test::mpi_exchange()) put(mpi, b);
    put(mpi, test::kMpiDataHighSap);
    put(dp, test::kMpiConnectRequest);
    put(dp, test::kMpiDataJob);
    put(dp, test::kSetPrm);
    put(dp, test::kDpv1Read);
    put(dp, test::kMpiDataHighSap);
    S7PduInfo job;
    job.direction = S7PduInfo::Direction::Inbound;
    job.src_ip = 0x7F000001;
    job.dst_ip = 0x7F000001;
    job.src_port = 40000;
    job.dst_port = 10102;
    job.comment = "door connection 1 -> CPU rack 0 slot 2";
    S7PduInfo answer = job;
    answer.direction = S7PduInfo::Direction::Outbound;
    std::swap(answer.src_port, answer.dst_port);
    ASSERT_TRUE(w->write_s7_pdu(s7, t + ms, test::kS7ReadJob, job));
    ASSERT_TRUE(w->write_s7_pdu(s7, t + 2 * ms, test::kS7ReadAnswer, answer));
    EXPECT_FALSE(w->write_s7_pdu(s7 + 5, t, test::kS7ReadJob));  // no such S7 interface
    ASSERT_TRUE(w->flush());
  }
  static void TearDownTestSuite() { std::filesystem::remove(s_path); }
  void SetUp() override {
    if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  }
  static std::string s_path;
};
std::string TsharkMpi::s_path;

TEST_F(TsharkMpi, ConnectionLayerFields) {
  const auto rows = ts::tshark_fields(
      s_path,
      {"frame.number", "_ws.col.Protocol", "pbmpi.pdu", "pbmpi.pdu_name", "pbmpi.msg_nr",
       "pbmpi.ack_nr", "pbmpi.subcode", "pbmpi.connect_params", "pbmpi.src", "pbmpi.dst",
       "pbmpi.line_marked"},
      "frame.interface_name == \"mpi0\"");
  ASSERT_EQ(rows.size(), 10u);
  const std::string params = "04008000020002010001" "00";
  EXPECT_EQ(rows[0], (R{"1", "MPI", "0xe0", "Connect request", "", "", "", params, "0:20", "2:0",
                        "1"}));
  EXPECT_EQ(rows[1], (R{"2", "MPI", "0xd0", "Connect confirm", "", "", "", params, "2:20", "0:20",
                        "1"}));
  EXPECT_EQ(rows[2], (R{"3", "MPI", "0x05", "Connection ack", "", "", "0x01", "", "0:20", "2:20",
                        "1"}));
  EXPECT_EQ(rows[3], (R{"4", "MPI", "0x05", "Connection ack", "", "", "0x01", "", "2:20", "0:20",
                        "1"}));
  EXPECT_EQ(rows[4], (R{"5", "MPI", "0xf1", "Data", "0", "", "", "", "0:20", "2:20", "1"}));
  EXPECT_EQ(rows[5], (R{"6", "MPI", "0xb0", "Data ack", "", "0", "0x01", "", "2:20", "0:20", "1"}));
  EXPECT_EQ(rows[6], (R{"7", "MPI", "0xf1", "Data", "0", "", "", "", "2:20", "0:20", "1"}));
  EXPECT_EQ(rows[7], (R{"8", "MPI", "0xb0", "Data ack", "", "0", "0x01", "", "0:20", "2:20", "1"}));
  EXPECT_EQ(rows[8], (R{"9", "MPI", "0x80", "Disconnect request", "", "", "", "", "0:20", "2:20",
                        "1"}));
  // SAP 50 is a DP SAP, but the interface is marked MPI: data message 1.
  EXPECT_EQ(rows[9], (R{"10", "MPI", "0xf1", "Data", "1", "", "", "", "0:20", "2:50", "1"}));
}

TEST_F(TsharkMpi, S7PduOfDataMessagesGoesToS7comm) {
  const auto rows = ts::tshark_fields(
      s_path,
      {"frame.number", "pbmpi.msg_nr", "s7comm.header.rosctr", "s7comm.param.func",
       "s7comm.param.itemcount", "s7comm.data.returncode", "pbmpi.s7_len"},
      "frame.interface_name == \"mpi0\" && s7comm");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0], (R{"5", "0", "1", "0x04", "1", "", "24"}));
  EXPECT_EQ(rows[1], (R{"7", "0", "3", "0x04", "1", "0xff", "28"}));
  const auto info = ts::tshark_info(s_path);
  ASSERT_EQ(info.size(), 17u);
  EXPECT_EQ(info[0], "SRD_high 0→2 MPI Connect request SAP 20→0 FCB=1 FCV=0");
  EXPECT_EQ(info[4],
            "SRD_high 0→2 MPI Data nr 0: S7 ROSCTR:[Job     ] Function:[Read Var] FCB=1 FCV=1");
  EXPECT_EQ(info[5], "SRD_low 2→0 MPI Data ack nr 0 FCB=1 FCV=1");
  EXPECT_EQ(info[6],
            "SRD_low 2→0 MPI Data nr 0: S7 ROSCTR:[Ack_Data] Function:[Read Var] FCB=0 FCV=1");
  EXPECT_EQ(info[8], "SRD_high 0→2 MPI Disconnect request FCB=0 FCV=1");
  // The high-SAP data message carries no S7 PDU (AA): shown, with a note, never a Lua error.
  EXPECT_EQ(info[9], "SRD_high 0→2 MPI Data nr 1 FCB=0 FCV=1");
}

TEST_F(TsharkMpi, NoDpFrameIsTakenForMpiOnAnUnmarkedInterface) {
  const auto rows = ts::tshark_fields(
      s_path, {"frame.number", "_ws.col.Protocol", "pbmpi.pdu", "pbmpi.line_marked", "pbdp.service",
               "s7comm.param.func"},
      "frame.interface_name == \"dp0\"");
  ASSERT_EQ(rows.size(), 5u);
  // MPI on an unmarked interface by the SAP rule (both SAPs below 49).
  EXPECT_EQ(rows[0], (R{"11", "MPI", "0xe0", "0", "", ""}));
  EXPECT_EQ(rows[1], (R{"12", "MPI", "0xf1", "0", "", "0x04"}));
  // DP frames with SAPs stay DP.
  EXPECT_EQ(rows[2][1], "DP");
  EXPECT_EQ(rows[2][2], "");
  EXPECT_EQ(rows[2][4], "Set_Prm.req");
  EXPECT_EQ(rows[3][1], "DP-V1");
  EXPECT_EQ(rows[3][2], "");
  // SAP 50 on an unmarked interface: not MPI.
  EXPECT_EQ(rows[4][2], "");
}

TEST_F(TsharkMpi, UpperPduRecordsDecodeWithS7commAlone) {
  for (bool with_script : {false, true}) {
    const auto r = ts::tshark(
        s_path,
        {"-Y", "frame.interface_name == \"s7door\"", "-T", "fields", "-E", "separator=|", "-e",
         "frame.number", "-e", "frame.protocols", "-e", "exported_pdu.heur_prot_name", "-e",
         "s7comm.header.rosctr", "-e", "s7comm.param.func", "-e", "s7comm.param.itemcount", "-e",
         "s7comm.data.returncode", "-e", "exported_pdu.src_port", "-e", "exported_pdu.dst_port",
         "-e", "_ws.col.Source", "-e", "frame.comment"},
        with_script);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out,
              "16|exported_pdu:s7comm|s7comm_cotp|1|0x04|1||40000|10102|127.0.0.1|"
              "door connection 1 -> CPU rack 0 slot 2\n"
              "17|exported_pdu:s7comm|s7comm_cotp|3|0x04|1|0xff|10102|40000|127.0.0.1|"
              "door connection 1 -> CPU rack 0 slot 2\n")
        << (with_script ? "with" : "without") << " the script";
  }
}

TEST_F(TsharkMpi, InterfacesAsDeclared) {
  const auto r = ts::tshark(s_path,
                            {"-T", "fields", "-E", "separator=|", "-e", "frame.interface_name",
                             "-e", "frame.interface_description", "-e", "frame.encap_type"},
                            /*with_dissector=*/false);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("mpi0|MPI 187.5 kbit/s, probe at PG 0|45\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dp0|PROFIBUS-DP 1.5 Mbit/s, probe at master 1|45\n"), std::string::npos)
      << r.out;
  // WTAP_ENCAP_WIRESHARK_UPPER_PDU
  EXPECT_NE(r.out.find("s7door|S7 PDUs (exported PDU for s7comm)|155\n"), std::string::npos)
      << r.out;
}

TEST(TsharkMpiRobustness, MutatedMpiFramesDecodeWithoutLuaErrors) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const auto path = test::temp_capture_path("pbvbus_tshark_mpi_garbage");
  {
    bus::Scheduler sched;
    bus::Line mpi(sched, "mpiA", bus::Baud::k187_5);
    bus::Line dp(sched, "dpA", bus::Baud::k187_5);
    auto w = PcapngWriter::open(path, {});
    ASSERT_TRUE(w);
    w->mark_mpi(mpi);
    test::MpiMutator mut(0x5EED'0187'0005ULL);
    for (int i = 0; i < 400; ++i)
      w->on_frame(test::tap_frame(i % 2 ? mpi : dp, mut.next_frame(), (i + 1) * 100'000));
  }
  const auto r = ts::tshark(path, {"-V"});
  std::filesystem::remove(path);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto at = r.out.find("Lua Error");
  EXPECT_EQ(at, std::string::npos) << r.out.substr(at > 1500 ? at - 1500 : 0, 2000);
  EXPECT_EQ(r.err.find("Lua"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("MPI connection layer"), std::string::npos);  // some still are MPI
}

}  // namespace
}  // namespace pbvbus::captures
