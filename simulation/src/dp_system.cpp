// DP master systems at run time (simulation/include/pbvbus/simulation/dp_system.hpp).
#include "pbvbus/simulation/dp_system.hpp"

#include <algorithm>
#include <stdexcept>

#include "pbvbus/dp/sap.hpp"

namespace pbvbus::tools {

namespace {

std::vector<dp::SlaveParams> slave_params(const DpMasterPlan& plan,
                                          const std::vector<DpSlavePlan>& slaves) {
  std::vector<dp::SlaveParams> out;
  for (int i : plan.slaves) out.push_back(slaves.at(static_cast<std::size_t>(i)).params);
  return out;
}

}  // namespace

DpMasterNode::DpMasterNode(const DpMasterPlan& plan, const std::vector<DpSlavePlan>& slaves,
                           const fdl::BusParams& params)
    : m_master(plan.params, slave_params(plan, slaves)), m_program(plan.outputs),
      m_program_off(plan.gateway_outputs), m_addresses(m_master.addresses()) {
  m_station = std::make_unique<fdl::ActiveStation>(plan.params.address, params, *this);
}

void DpMasterNode::on_power_on(bus::Ticks now) {
  m_tokens = 0;
  m_master.on_power_on(now);
}

bool DpMasterNode::next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) {
  if (!m_master.next_request(prio, now, out)) {
    return false;
  }
  if (out.da == fdl::kBroadcast && out.dsap == dp::kSapGlobalControl) ++m_global_controls;
  return true;
}

void DpMasterNode::on_token(bus::Ticks now, bus::Ticks trr) {
  ++m_tokens;
  if (m_cpu) {  // a CPU's DP interface: its process image
    m_cpu(m_master);
    m_master.on_token(now, trr);
    return;
  }
  // Served by a gateway: its clients own the outputs (scenario.proto, DpMaster.outputs).
  if (m_program_off) {
    m_master.on_token(now, trr);
    return;
  }
  // The "PLC program": one output update per token receipt, i.e. per bus cycle.
  const auto value =
      static_cast<std::uint8_t>(m_program == scenario::DpMaster::COUNT ? (m_tokens & 0xFF) : 0);
  for (std::uint8_t a : m_addresses) {
    dp::MasterImage& img = m_master.image(a);
    for (std::size_t mod = 0; mod < img.modules(); ++mod) {
      const std::size_t n = img.module(mod).out_len;
      if (n == 0) continue;
      m_buf.assign(n, value);
      img.write_outputs(mod, m_buf);
    }
  }
  m_master.on_token(now, trr);
}

DpSlaveNode::DpSlaveNode(const DpSlavePlan& plan, const fdl::BusParams& params) {
  devices::SlaveModelOptions o;
  o.address = plan.address;
  o.bus_params = params;
  if (plan.tsdr != 0) o.tsdr = plan.tsdr;
  o.mutant = plan.mutant;  // test-only (devices/slave_mutant.hpp)
  std::vector<devices::ModuleChoice> mods;
  for (std::size_t i : plan.gsd_modules) mods.push_back(devices::ModuleChoice::at(i));
  auto b = devices::SlaveModel::build(*plan.gsd, mods, o);
  if (!b.ok())
    throw std::runtime_error("DP slave " + std::to_string(plan.address) + ": " +
                             (b.errors.empty() ? std::string("cannot be built") : b.errors.front()));
  m_model = std::move(b.model);
  devices::SlaveModel& model = *m_model;
  apply_io_plan(
      plan, model.application(),
      [&](std::size_t m, devices::IoBehaviour beh) { return model.set_behaviour(m, std::move(beh)); },
      [&](std::size_t m, std::size_t off, std::size_t w, devices::IoBehaviour beh) {
        return model.add_channel_behaviour(m, off, w, std::move(beh));
      });
}

void apply_io_plan(const DpSlavePlan& plan, const dp::SlaveApplication& app,
                   const std::function<std::string(std::size_t, devices::IoBehaviour)>& set,
                   const std::function<std::string(std::size_t, std::size_t, std::size_t,
                                                   devices::IoBehaviour)>& add) {
  std::optional<std::size_t> first_out;
  for (std::size_t m = 0; m < app.modules(); ++m)
    if (app.module(m).out_len > 0 && !first_out) first_out = m;
  for (std::size_t m = 0; m < app.modules(); ++m) {
    const dp::ModuleLayout& ml = app.module(m);
    if (ml.in_len == 0) continue;
    devices::IoBehaviour beh = devices::IoBehaviour::constant_value({});
    if (plan.io == scenario::DpSlave::COUNTER) {
      beh = devices::IoBehaviour::counter_per_cycle();
    } else if (plan.io == scenario::DpSlave::ECHO && (ml.out_len > 0 || first_out)) {
      beh = devices::IoBehaviour::echo(ml.out_len > 0 ? std::optional<std::size_t>(m) : first_out);
    }
    if (std::string why = set(m, beh); !why.empty())
      throw std::runtime_error("DP slave " + std::to_string(plan.address) + ": " + why);
  }
  for (const DpIoPlan& io : plan.io_behaviours) {
    const std::string why = io.whole ? set(io.module, io.behaviour)
                                     : add(io.module, io.offset, io.width, io.behaviour);
    if (!why.empty())
      throw std::runtime_error("DP slave " + std::to_string(plan.address) + ": " + why);
  }
}

DpSlaveNode::~DpSlaveNode() = default;
dp::SlaveEngine& DpSlaveNode::engine() { return m_model->engine(); }
const dp::SlaveEngine& DpSlaveNode::engine() const {
  return const_cast<devices::SlaveModel&>(*m_model).engine();
}
std::uint64_t DpSlaveNode::data_exchanges() const { return m_model->dp_cycles(); }

std::vector<std::string> diag_bit_names(std::span<const std::uint8_t> d) {
  static constexpr const char* kNames[3][8] = {
      {"Station_Non_Existent", "Station_Not_Ready", "Cfg_Fault", "Ext_Diag", "Not_Supported",
       "Invalid_Slave_Response", "Prm_Fault", "Master_Lock"},
      {"Prm_Req", "Stat_Diag", "always_1", "WD_On", "Freeze_Mode", "Sync_Mode", "reserved",
       "Deactivated"},
      {"", "", "", "", "", "", "", "Ext_Diag_Overflow"}};
  std::vector<std::string> out;
  for (std::size_t o = 0; o < 3 && o < d.size(); ++o)
    for (int b = 0; b < 8; ++b)
      if ((d[o] >> b) & 1) out.emplace_back(kNames[o][b][0] ? kNames[o][b] : "reserved");
  return out;
}

DpSlaveView dp_slave_view(const DpSlaveNode& node, const DpSlavePlan& p, const std::string& line) {
  // The engine's diagnosis builder and the station are not const; reading them changes nothing.
  auto& model = const_cast<devices::SlaveModel&>(const_cast<DpSlaveNode&>(node).model());
  dp::SlaveEngine& eng = model.engine();
  DpSlaveView v;
  v.line = line;
  v.address = model.address();
  v.model = p.model;
  v.gsd = p.gsd_path;
  v.modules = p.module_names;
  if (p.master != dp::kNoMaster) v.master = p.master;
  v.state = std::string(dp::to_string(eng.state()));
  if (eng.master_address() != dp::kNoMaster) v.owner = eng.master_address();
  if (eng.watchdog_on()) v.watchdog = eng.watchdog_time();
  const auto d = eng.current_diag();
  v.diag.assign(d.begin(), d.end());
  v.diag_bits = diag_bit_names(v.diag);
  v.input_len = eng.layout().inputs;
  v.output_len = eng.layout().outputs;
  const auto in = eng.last_inputs();
  const auto out = eng.last_outputs();
  v.inputs.assign(in.begin(), in.end());
  v.outputs.assign(out.begin(), out.end());
  v.stats = eng.stats();
  v.fdl = model.station().stats();
  return v;
}

DpMasterReport dp_master_report(const DpMasterNode& node,
                                const std::vector<const DpSlaveNode*>& slaves,
                                const std::vector<const DpSlavePlan*>& plans,
                                const std::string& line, bus::Baud baud) {
  std::vector<const dp::SlaveEngine*> engines;
  for (const DpSlaveNode* n : slaves) engines.push_back(&n->engine());
  return dp_master_report(node.master(), node.global_controls(), engines, plans, line, baud);
}

DpMasterReport dp_master_report(const dp::Master& m, std::uint64_t global_controls,
                                const std::vector<const dp::SlaveEngine*>& engines,
                                const std::vector<const DpSlavePlan*>& plans,
                                const std::string& line, bus::Baud baud) {
  DpMasterReport r;
  r.address = m.address();
  r.line = line;
  r.baud = baud;
  r.mode = std::string(dp::to_string(m.mode()));
  r.global_controls = global_controls;
  r.data_control_time = m.params().data_control_time;
  r.equidistance = m.equidistance();
  for (std::size_t i = 0; i < engines.size(); ++i) {
    const DpSlavePlan& p = *plans[i];
    const dp::SlaveEngine& eng = *engines[i];
    DpSlaveReport s;
    s.address = p.address;
    s.master = p.master;
    s.model = p.model;
    s.modules = p.module_names;
    s.state = std::string(dp::to_string(m.slave_state(p.address)));
    s.slave_state = std::string(dp::to_string(eng.state()));
    const auto d = m.slave_diag(p.address);
    s.diag.assign(d.begin(), d.end());
    s.diag_bits = diag_bit_names(s.diag);
    const dp::MasterImage& img = m.image(p.address);
    s.input_len = img.input_length();
    s.output_len = img.output_length();
    s.inputs.assign(s.input_len, 0);
    if (s.input_len > 0) img.read_all_inputs(s.inputs);
    // What arrived at the device (after Clear_Data, the safe state): module by module.
    s.outputs.assign(s.output_len, 0);
    dp::SlaveEngine& e = const_cast<dp::SlaveEngine&>(eng);  // the application's reads are const
    const dp::SlaveApplication& app = e.application();
    std::vector<std::uint8_t> buf;
    for (std::size_t mod = 0; mod < app.modules(); ++mod) {
      const dp::ModuleLayout& ml = app.module(mod);
      if (ml.out_len == 0) continue;
      buf.assign(ml.out_len, 0);
      if (app.read_outputs(mod, buf) && ml.out_offset + ml.out_len <= s.outputs.size())
        std::copy(buf.begin(), buf.end(), s.outputs.begin() + static_cast<std::ptrdiff_t>(ml.out_offset));
    }
    s.stats = m.slave_stats(p.address);
    s.cycle_median = m.cycle_median(p.address);
    r.slaves.push_back(std::move(s));
  }
  return r;
}

}  // namespace pbvbus::tools
