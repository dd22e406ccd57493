// The Hot Standby pair on a real DP line (hsby_dp_line.hpp).
#include "pbvbus/quantum/hsby_dp_line.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "pbvbus/quantum/transfer_area.hpp"

namespace pbvbus::quantum {

namespace {

// One input octet (DI 8) and one output word (DO 16): identifiers 0x10 (1 byte input) and 0x60
// (1 word output) of IEC 61158-6-3 Chk_Cfg (the general identifier format).
constexpr std::uint8_t kHdlInId = 0x10;
constexpr std::uint8_t kHdlOutId = 0x60;
constexpr std::uint16_t kHdlIdent = 0x1234;

}  // namespace

SlaveProbe::SlaveProbe(int index, dp::SlaveConfig cfg) : m_index(index), m_engine(std::move(cfg)) {}

std::uint16_t SlaveProbe::output_word() const {
  const auto o = m_engine.last_outputs();
  if (o.size() < 2) return 0;
  return static_cast<std::uint16_t>((o[0] << 8) | o[1]);
}

void SlaveProbe::on_request(const fdl::Indication& ind, fdl::Reply& reply) {
  const std::uint64_t before = m_engine.stats().data_exchange;
  m_engine.on_request(ind, reply);
  if (on_dx && m_engine.stats().data_exchange != before &&
      m_engine.state() == dp::SlaveState::DataExch)
    on_dx(m_index, output_word(), ind.now);
}

HsbyDpLine::HsbyDpLine(const HsbyDpLineOptions& o)
    : m_o(o), m_line(m_sched, "dp", o.baud) {
  if (o.slaves < 1 || o.slaves > 100 || o.first_slave + o.slaves > 125 ||
      o.master_address >= o.first_slave)
    throw std::invalid_argument("HsbyDpLine: 1..100 slaves above the master address, below 126");
  if (o.output_base + static_cast<std::uint32_t>(o.slaves) > o.sizes.holding ||
      o.input_base + static_cast<std::uint32_t>(o.slaves) > o.sizes.input_regs ||
      o.counter_register >= o.sizes.holding)
    throw std::invalid_argument("HsbyDpLine: the I/O map or the counter lies outside state RAM");
  m_bp = fdl::BusParams::defaults(o.baud);
  m_bp.hsa = static_cast<std::uint8_t>(o.first_slave + o.slaves);
  m_bound = token_timeout(m_bp, o.master_address);

  std::vector<dp::SlaveParams> sp;
  std::vector<DpIoMap> map;
  for (int k = 0; k < o.slaves; ++k) {
    dp::SlaveParams p;
    p.address = slave_address(k);
    p.name = "slave " + std::to_string(p.address);
    p.ident = kHdlIdent;
    p.wd_fact_1 = 1;
    p.wd_fact_2 = o.watchdog_factor;
    p.modules = {{{kHdlInId}, "DI 8"}, {{kHdlOutId}, "DO 16"}};
    sp.push_back(std::move(p));
    map.push_back(DpIoMap{slave_address(k),
                          Reference{RefType::Register3x, o.input_base + static_cast<std::uint32_t>(k)},
                          Reference{RefType::Register4x, o.output_base + static_cast<std::uint32_t>(k)}});
  }
  dp::MasterParams mp;
  mp.address = o.master_address;
  for (int r = 0; r < 2; ++r) {
    m_heads[static_cast<std::size_t>(r)] = std::make_unique<DpHead>(mp, sp, m_bp, map, m_bound);
    m_heads[static_cast<std::size_t>(r)]->attach(
        m_line, "DP master " + std::to_string(o.master_address) + " (rack " + std::to_string(r) + ")");
  }
  for (int k = 0; k < o.slaves; ++k) {
    dp::SlaveConfig c;
    c.ident = kHdlIdent;
    c.modules = {{{kHdlInId}, "DI 8"}, {{kHdlOutId}, "DO 16"}};
    m_probes.push_back(std::make_unique<SlaveProbe>(k, std::move(c)));
    m_stations.push_back(
        std::make_unique<fdl::PassiveStation>(slave_address(k), m_bp, *m_probes.back()));
    m_slave_att.push_back(
        m_line.attach(*m_stations.back(), "slave " + std::to_string(slave_address(k))));
  }

  TransferConfig tc;  // the 12K default
  tc.non_transfer = o.non_transfer;
  tc.command_register = 0;
  TransferPlanResult plan = plan_transfer(tc, o.sizes);
  if (!plan.plan) throw std::invalid_argument("HsbyDpLine: transfer plan refused: " + plan.error);
  HsbyPairParams pp;
  pp.sizes = o.sizes;
  pp.plan = *plan.plan;
  pp.command_register = 0;
  pp.scan_time = o.scan_time;
  pp.transfer_time = o.transfer_time;
  pp.update_time = o.update_time;
  pp.line_check_delay = m_bound;
  m_pair = std::make_unique<HsbyPair>(m_sched, pp,
                                      std::array<IoHead*, 2>{m_heads[0].get(), m_heads[1].get()});
  m_pair->set_logic(counter_logic(nullptr));
}

void HsbyDpLine::start() {
  for (bus::AttachmentId a : m_slave_att) m_line.set_power(a, true);
  m_pair->power_on(0);
  m_pair->power_on(1);
}

bool HsbyDpLine::all_in_data_exchange() const {
  for (const auto& p : m_probes)
    if (p->engine().state() != dp::SlaveState::DataExch) return false;
  return true;
}

bool HsbyDpLine::standby_shadows_all() const {
  const int s = m_pair->standby();
  if (s < 0) return false;
  const DpHead& h = *m_heads[static_cast<std::size_t>(s)];
  for (int k = 0; k < slave_count(); ++k)
    if (!h.master().shadow_in_dx(slave_address(k))) return false;
  return true;
}

UserLogic HsbyDpLine::counter_logic(std::function<void(std::uint16_t, bus::Ticks)> hook) const {
  const std::uint32_t reg = m_o.counter_register;
  const std::uint32_t base = m_o.output_base;
  const auto n = static_cast<std::uint32_t>(m_o.slaves);
  return [reg, base, n, hook = std::move(hook)](StateRam& ram, bus::Ticks now) {
    std::uint16_t v = static_cast<std::uint16_t>(ram.holding(reg) + 1);
    if (v == 0) v = 1;
    ram.set_holding(reg, v);
    for (std::uint32_t k = 0; k < n; ++k) ram.set_holding(base + k, v);
    if (hook) hook(v, now);
  };
}

}  // namespace pbvbus::quantum
