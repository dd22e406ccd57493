#pragma once
// The Hot Standby pair on a real DP line (docs/quantum-hsby-campaign.md "The system"): one
// bus::Line, each rack's DP master module (dp_head.hpp) at the same address with the same
// master and slave parameters, and N DP slaves (dp::SlaveEngine, watchdog on) whose one output
// word and one input octet sit in state RAM through the I/O map:
//   slave k (address first_slave + k): outputs 4x output_base + k (one word, first octet in the
//   high byte), inputs 3x input_base + k (the octet in the high byte).
// The transfer plan is plan_transfer's 12K default over the (small) state RAM with the
// non-transfer area and the command register at 4x 0 (400001). line_check_delay = the heads'
// silence bound, TTO of the master address (dp_head.hpp). The default logic (counter_logic)
// increments a 16-bit counter in 4x counter_register (never 0: 0xFFFF -> 1) and writes it into
// every slave's output word.
//
// Each slave sits behind a probe (SlaveProbe) that reports, after every Data_Exchange the slave
// accepted, the output word as the slave holds it: the campaign's and the tests' view from the
// slave side, not the master's image.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/passive_station.hpp"
#include "pbvbus/quantum/dp_head.hpp"
#include "pbvbus/quantum/hsby_pair.hpp"
#include "pbvbus/quantum/transfer_plan.hpp"

namespace pbvbus::quantum {

struct HsbyDpLineOptions {
  bus::Baud baud = bus::Baud::k1_5M;
  int slaves = 3;
  std::uint8_t master_address = 1;
  std::uint8_t first_slave = 10;
  /// The slaves' watchdog: 10 ms x 1 x watchdog_factor (Set_Prm WD_Fact_1 = 1, WD_Fact_2).
  std::uint8_t watchdog_factor = 10;
  bus::Ticks scan_time = 20 * bus::kTicksPerMs;
  bus::Ticks transfer_time = 0;  ///< 0: the pair's default (scan_time / 4)
  bus::Ticks update_time = 100 * bus::kTicksPerMs;
  StateRamSizes sizes{64, 64, 32, 256};
  NonTransferArea non_transfer{200, 4};
  std::uint32_t counter_register = 10;  ///< 4x index
  std::uint32_t output_base = 100;      ///< 4x index of slave 0's output word
  std::uint32_t input_base = 0;         ///< 3x index of slave 0's input octet
};

/// A fdl::ResponderUser in front of a dp::SlaveEngine: forwards everything and, after each
/// Data_Exchange the engine counted, calls `on_dx(k, output word, now)`.
class SlaveProbe final : public fdl::ResponderUser {
 public:
  SlaveProbe(int index, dp::SlaveConfig cfg);
  dp::SlaveEngine& engine() { return m_engine; }
  const dp::SlaveEngine& engine() const { return m_engine; }
  /// The output word as the slave holds it (its last accepted Data_Exchange).
  std::uint16_t output_word() const;
  std::function<void(int, std::uint16_t, bus::Ticks)> on_dx;

  void on_power_on(bus::Ticks now) override { m_engine.on_power_on(now); }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override;
  bus::Ticks next_deadline() const override { return m_engine.next_deadline(); }
  void on_time(bus::Ticks now) override { m_engine.on_time(now); }

 private:
  int m_index;
  dp::SlaveEngine m_engine;
};

class HsbyDpLine {
 public:
  /// Throws std::invalid_argument when the transfer plan is refused or the options are
  /// unusable (no slave, more than 100, an I/O map outside state RAM).
  explicit HsbyDpLine(const HsbyDpLineOptions& o);
  HsbyDpLine(const HsbyDpLine&) = delete;
  HsbyDpLine& operator=(const HsbyDpLine&) = delete;

  /// Powers the slaves, then rack 0 (primary) and rack 1 (standby).
  void start();
  /// Runs to `t` (virtual time).
  void run_until(bus::Ticks t) { m_sched.run_until(t); }
  bus::Ticks now() const { return m_sched.now(); }

  const HsbyDpLineOptions& options() const { return m_o; }
  bus::Scheduler& scheduler() { return m_sched; }
  bus::Line& line() { return m_line; }
  HsbyPair& pair() { return *m_pair; }
  const HsbyPair& pair() const { return *m_pair; }
  DpHead& head(int rack) { return *m_heads[static_cast<std::size_t>(rack == 1 ? 1 : 0)]; }
  int slave_count() const { return static_cast<int>(m_probes.size()); }
  std::uint8_t slave_address(int k) const {
    return static_cast<std::uint8_t>(m_o.first_slave + k);
  }
  SlaveProbe& slave(int k) { return *m_probes.at(static_cast<std::size_t>(k)); }
  const SlaveProbe& slave(int k) const { return *m_probes.at(static_cast<std::size_t>(k)); }
  bus::AttachmentId slave_attachment(int k) const {
    return m_slave_att.at(static_cast<std::size_t>(k));
  }
  /// The silence bound of both heads and the pair's line_check_delay: TTO(master_address).
  bus::Ticks silence_bound() const { return m_bound; }

  /// Every slave in data exchange (slave side) and the standby's module (if any) shadowing
  /// every slave in data exchange.
  bool all_in_data_exchange() const;
  bool standby_shadows_all() const;

  /// The default program: the counter in 4x counter_register, +1 a scan (0xFFFF -> 1), into
  /// every output word; `hook(value, now)` (may be null) is told each value computed.
  UserLogic counter_logic(std::function<void(std::uint16_t, bus::Ticks)> hook) const;

 private:
  HsbyDpLineOptions m_o;
  bus::Scheduler m_sched;
  bus::Line m_line;
  fdl::BusParams m_bp;
  bus::Ticks m_bound = 0;
  std::array<std::unique_ptr<DpHead>, 2> m_heads;
  std::vector<std::unique_ptr<SlaveProbe>> m_probes;
  std::vector<std::unique_ptr<fdl::PassiveStation>> m_stations;
  std::vector<bus::AttachmentId> m_slave_att;
  std::unique_ptr<HsbyPair> m_pair;
};

}  // namespace pbvbus::quantum
