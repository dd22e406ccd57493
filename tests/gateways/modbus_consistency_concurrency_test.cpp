// Modbus consistency under concurrency (docs/gateway-modbus.md): four libmodbus TCP clients, each
// on its own connection and thread, write the 16 holding registers of a consistent 16-word
// module (PBVB0A04.gsd, identifier 0xFF) and read them back while the bus runs paced on the test
// thread. Every value a client writes is one pattern in all 16 registers:
//   register value = (client id << 12) | (sequence & 0xFFF)
// so a torn image (half of one write, half of another) shows as registers that differ.
//
// What is checked:
//  - every FC04 read (input registers: the slave ECHOES its outputs, so they are a whole write
//    as the slave received it one DP cycle earlier), every FC03 read and every FC23 read has 16
//    equal registers;
//  - on the wire: every Data_Exchange request telegram the master sent to the slave (whole-line
//    tap, SD2 to DA 4 without address extension, 32 data octets) carries 16 equal words;
//  - in the slave: the outputs the slave model holds, sampled after every change (a scheduler
//    event every 10 us virtual comparing SlaveApplication::outputs_generation), are 16 equal
//    words;
//  - more than one writer was seen on the wire and in the reads (the clients really raced).
// Layer-level only (no tools/): bus::Line at 12 Mbit/s, fdl::ActiveStation + dp::Master,
// devices::SlaveModel, DpMasterSource + ModbusGateway + ModbusTcpServer on a bus::PacedRunner
// at speed 20/1. Named *_concurrency_test so CI also runs it under TSan.
#include <gtest/gtest.h>
#include <modbus.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/gateways/dp_master_source.hpp"
#include "pbvbus/gateways/modbus_gateway.hpp"
#include "pbvbus/gateways/modbus_tcp_server.hpp"

namespace pbvbus::gateways {
namespace {

constexpr bus::Baud kBaud = bus::Baud::k12M;
constexpr std::uint8_t kSlave = 4;
constexpr int kWords = 16;
constexpr int kClients = 4;
constexpr int kIterations = 150;  // per client: 2 writes + 3 reads each (3 000 requests total)

/// The wire check: Data_Exchange requests master -> slave 4. An SD2 frame is
///   68 LE LEr 68 DA SA FC DU... FCS 16
/// with LE = 3 + |DU|; Data_Exchange uses the default SAP, so DA and SA have bit 7 clear (the
/// start-up services Set_Prm/Chk_Cfg/Slave_Diag carry SAPs, DA bit 7 set, and are skipped).
/// The DU of a Data_Exchange request to this slave is its 32 output octets: LE = 35.
class OutputTelegramTap final : public bus::Tap {
 public:
  void on_frame(const bus::TapFrame& f) override {
    const auto& b = f.bytes;
    if (b.size() != 6u + 35u || b[0] != 0x68 || b[1] != 35 || b[4] != kSlave) return;
    ++telegrams;
    const std::uint16_t w0 = static_cast<std::uint16_t>(b[7] << 8 | b[8]);
    for (int i = 1; i < kWords; ++i) {
      const std::size_t at = 7u + 2u * static_cast<std::size_t>(i);
      if (static_cast<std::uint16_t>(b[at] << 8 | b[at + 1]) != w0) {
        ++torn;
        return;
      }
    }
    if (w0 >> 12 != 0) writers.insert(w0 >> 12);  // 0 = the outputs before any write
  }
  std::uint64_t telegrams = 0;
  std::uint64_t torn = 0;
  std::set<int> writers;
};

/// The slave-side check: every 10 us virtual, if the slave model got new outputs, copy them as
/// one unit (SlaveApplication::read_outputs) and check the 16 words.
class SlaveOutputWatch final : public bus::EventTarget {
 public:
  SlaveOutputWatch(bus::Scheduler& s, devices::SlaveModel& m) : m_s(s), m_m(m) {
    m_s.schedule(kPeriod, *this);
  }
  void on_event(bus::Ticks now, std::uint64_t) override {
    const std::uint32_t g = m_m.application().outputs_generation(0);
    if (g != m_gen) {
      m_gen = g;
      std::array<std::uint8_t, 2 * kWords> o{};
      if (m_m.application().read_outputs(0, o)) {
        ++samples;
        bool whole = true;
        for (int i = 1; i < kWords; ++i)
          whole = whole && o[2u * static_cast<std::size_t>(i)] == o[0] &&
                  o[2u * static_cast<std::size_t>(i) + 1] == o[1];
        if (!whole) ++torn;
      }
    }
    m_s.schedule(now + kPeriod, *this);
  }
  std::uint64_t samples = 0;
  std::uint64_t torn = 0;

 private:
  static constexpr bus::Ticks kPeriod = 10 * bus::kTicksPerUs;
  bus::Scheduler& m_s;
  devices::SlaveModel& m_m;
  std::uint32_t m_gen = 0;
};

struct ClientResult {
  int reads = 0;
  int torn_reads = 0;
  int errors = 0;
  std::string first_error;
  std::set<int> writers_seen;  ///< client ids seen in FC04 reads
};

bool all_equal(const std::uint16_t* r) {
  return std::all_of(r, r + kWords, [&](std::uint16_t v) { return v == r[0]; });
}

void client(int id, int port, ClientResult& res, std::atomic<int>& done) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
  auto fail = [&](const char* what) {
    ++res.errors;
    if (res.first_error.empty()) res.first_error = std::string(what) + ": " + modbus_strerror(errno);
  };
  if (ctx == nullptr || modbus_set_slave(ctx, kSlave) != 0) {
    fail("modbus_new_tcp");
  } else {
    modbus_set_response_timeout(ctx, 10, 0);  // generous: TSan and a loaded CI machine
    if (modbus_connect(ctx) != 0) {
      fail("connect");
    } else {
      std::array<std::uint16_t, kWords> w{}, r{};
      auto check = [&](const std::uint16_t* regs, bool ir) {
        ++res.reads;
        if (!all_equal(regs)) ++res.torn_reads;
        else if (ir && regs[0] >> 12 != 0) res.writers_seen.insert(regs[0] >> 12);
      };
      int seq = 0;
      for (int it = 0; it < kIterations && res.errors == 0; ++it) {
        w.fill(static_cast<std::uint16_t>(id << 12 | (++seq & 0xFFF)));
        if (modbus_write_registers(ctx, 0, kWords, w.data()) != kWords) fail("FC16");
        if (modbus_read_input_registers(ctx, 0, kWords, r.data()) != kWords) fail("FC04");
        else check(r.data(), true);
        if (modbus_read_registers(ctx, 0, kWords, r.data()) != kWords) fail("FC03");
        else check(r.data(), false);
        w.fill(static_cast<std::uint16_t>(id << 12 | (++seq & 0xFFF)));
        if (modbus_write_and_read_registers(ctx, 0, kWords, w.data(), 0, kWords, r.data()) !=
            kWords)
          fail("FC23");
        else check(r.data(), false);
      }
      modbus_close(ctx);
    }
  }
  if (ctx != nullptr) modbus_free(ctx);
  done.fetch_add(1);
}

// The wire check can fail: a hand-built Data_Exchange request (SD2) with one word from another
// write counts as torn; the same telegram whole counts writer 1.
//   68 23 23 68 | DA 04 SA 01 FC 5D (SRD_high, FCV=1 FCB=0: 0x40|0x10|0x0D) | 32 octets | FCS 16
//   LE = 0x23 = 35 = 3 + 32. DU = 16 words 0x1001 (writer 1, sequence 1).
//   FCS = (04 + 01 + 5D + 16 x (10 + 01)) mod 256 = (0x62 + 0x110) mod 256 = 0x172 mod 256 = 0x72;
//   with word 5 = 0x2001: 0x62 + 15 x 0x11 + 0x21 = 0x62 + 0x120 = 0x182 -> 0x82.
TEST(ModbusConsistency, WireCheckCountsATornTelegram) {
  std::vector<std::uint8_t> f{0x68, 0x23, 0x23, 0x68, 0x04, 0x01, 0x5D};
  for (int i = 0; i < kWords; ++i) {
    f.push_back(0x10);
    f.push_back(0x01);
  }
  f.push_back(0x72);
  f.push_back(0x16);
  OutputTelegramTap tap;
  bus::TapFrame tf;
  tf.bytes = f;
  tap.on_frame(tf);
  EXPECT_EQ(tap.telegrams, 1u);
  EXPECT_EQ(tap.torn, 0u);
  EXPECT_EQ(tap.writers, (std::set<int>{1}));
  f[7 + 2 * 5] = 0x20;
  f[7 + 2 * kWords] = 0x82;
  tf.bytes = f;
  tap.on_frame(tf);
  EXPECT_EQ(tap.telegrams, 2u);
  EXPECT_EQ(tap.torn, 1u);
  // A Set_Prm-like frame (DA with the SAP bit, 0x84) is not a Data_Exchange request.
  f[4] = 0x84;
  tf.bytes = f;
  tap.on_frame(tf);
  EXPECT_EQ(tap.telegrams, 2u);
}

TEST(ModbusConsistency, FourClientsNeverSeeOrSendATornImage) {
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  bp.hsa = 12;
  auto gsd = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A04.gsd");
  ASSERT_TRUE(gsd.ok());
  const std::vector<devices::ModuleChoice> mods{devices::ModuleChoice::at(0)};
  auto sp = devices::master_slave_params(*gsd.file, mods, kSlave);
  ASSERT_TRUE(sp.ok());
  dp::MasterParams mp;
  mp.address = 1;
  dp::Master master(mp, std::vector<dp::SlaveParams>{*sp.value});
  fdl::ActiveStation station(mp.address, bp, master);
  line.attach(station, "master 1");
  devices::SlaveModelOptions so;
  so.address = kSlave;
  so.bus_params = bp;
  auto built = devices::SlaveModel::build(*gsd.file, mods, so);
  ASSERT_TRUE(built.ok());
  devices::SlaveModel& slave = *built.model;
  ASSERT_EQ(slave.set_behaviour(0, devices::IoBehaviour::echo()), "");
  line.attach(slave, "slave 4");
  OutputTelegramTap tap;
  line.add_tap(tap);
  SlaveOutputWatch watch(sched, slave);

  DpMasterSource src(master, "dp_master 1 on dp");
  ModbusGateway gw(src);
  ASSERT_TRUE(gw.engine_ok());
  bus::PacedRunner runner(sched, bus::Speed{20, 1});
  ModbusTcpServer srv(runner.io_context(), gw, {"127.0.0.1", 0});

  line.start();
  sched.run_until(300 * bus::kTicksPerMs);  // start-up, fast
  ASSERT_EQ(master.slave_stats(kSlave).failures, 0u);
  ASSERT_GT(master.slave_stats(kSlave).data_exchanges, 0u);

  std::array<ClientResult, kClients> res{};
  std::atomic<int> done{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kClients; ++i)
    threads.emplace_back(client, i + 1, static_cast<int>(srv.port()), std::ref(res[static_cast<std::size_t>(i)]),
                         std::ref(done));
  // Run the bus on this thread in slices of 20 ms virtual (1 ms wall at 20/1) until the clients
  // are done; 120 s wall is only a generous upper bound (the run takes a few seconds).
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (done.load() < kClients && std::chrono::steady_clock::now() < give_up)
    runner.run_for(20 * bus::kTicksPerMs);
  const bool finished = done.load() == kClients;
  if (!finished) srv.close();  // lets clients stuck in a read fail instead of hanging the join
  for (auto& t : threads) t.join();
  runner.run_for(5 * bus::kTicksPerMs);  // the last write reaches the slave
  srv.close();
  ASSERT_TRUE(finished) << "clients did not finish within 120 s wall";

  std::set<int> read_writers;
  for (int i = 0; i < kClients; ++i) {
    const ClientResult& r = res[static_cast<std::size_t>(i)];
    EXPECT_EQ(r.errors, 0) << "client " << i + 1 << ": " << r.first_error;
    EXPECT_EQ(r.reads, 3 * kIterations) << "client " << i + 1;
    EXPECT_EQ(r.torn_reads, 0) << "client " << i + 1;
    read_writers.insert(r.writers_seen.begin(), r.writers_seen.end());
  }
  EXPECT_EQ(tap.torn, 0u);
  EXPECT_EQ(watch.torn, 0u);
  EXPECT_GT(tap.telegrams, 100u);
  EXPECT_GT(watch.samples, 0u);
  // The clients raced: more than one writer's pattern reached the slave and came back.
  EXPECT_GE(tap.writers.size(), 2u);
  EXPECT_GE(read_writers.size(), 2u);
  EXPECT_EQ(master.slave_stats(kSlave).failures, 0u);
  EXPECT_EQ(srv.stats().exceptions, 0u);
  RecordProperty("telegrams", static_cast<int>(tap.telegrams));
  RecordProperty("slave_samples", static_cast<int>(watch.samples));
  RecordProperty("writers_on_wire", static_cast<int>(tap.writers.size()));
}

}  // namespace
}  // namespace pbvbus::gateways
