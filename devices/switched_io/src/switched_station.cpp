// A switched station on two lines (switched_station.hpp).
#include "pbvbus/switched_io/switched_station.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace pbvbus::devices {

// --- the FDL station's user: inputs, DP cycle count, then the RedundantSlave's interface -------

class SwitchedStationModel::User final : public fdl::ResponderUser {
 public:
  User(SwitchedStationModel& m, int i) : m_model(m), m_i(i) {}
  void on_power_on(bus::Ticks now) override { m_model.m_rs->interface(m_i).on_power_on(now); }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override {
    redundancy::RedundantSlave& rs = *m_model.m_rs;
    dp::SlaveEngine& e = rs.engine(m_i);
    const bool dx = !ind.dsap && !ind.ssap && !ind.broadcast() &&
                    (ind.fn == fdl::RequestFn::SrdHigh || ind.fn == fdl::RequestFn::SrdLow) &&
                    e.state() == dp::SlaveState::DataExch && ind.sa == e.master_address();
    m_model.refresh_inputs(ind.now);
    rs.interface(m_i).on_request(ind, reply);
    if (dx && rs.role(m_i) == redundancy::Role::Primary) ++m_model.m_dp_cycles;
  }
  // The model drives the RedundantSlave's deadline itself, on both lines (rearm_all()).
  bus::Ticks next_deadline() const override { return bus::kNever; }
  void on_time(bus::Ticks) override {}

 private:
  SwitchedStationModel& m_model;
  int m_i;
};

// --- the FDL station's port: forwards to the interface device's port, multiplexes the timer ----

class SwitchedStationModel::Port final : public bus::DevicePort {
 public:
  Port(SwitchedStationModel& m, Iface& f) : m_model(m), m_if(f) {}
  bus::Ticks now() const override;
  bus::Baud baud() const override;
  void transmit(bus::Ticks start, std::span<const std::uint8_t> bytes) override;
  void set_timer(bus::Ticks at) override;
  bool receiving() const override;
  void receive_filter_changed() override;

 private:
  SwitchedStationModel& m_model;
  Iface& m_if;
};

class SwitchedStationModel::Iface final : public bus::Device {
 public:
  Iface(SwitchedStationModel& m, int i, const fdl::BusParams& bp)
      : m_model(m), m_user(m, i), m_port(m, *this),
        m_station(m.m_address, bp, m_user, m.m_tsdr) {
    m_station.bind(m_port);
  }
  void on_power_on(bus::Ticks now) override {
    m_powered = true;
    m_station_timer = bus::kNever;
    m_armed = bus::kNever;
    m_station.on_power_on(now);
    m_model.after_call();
  }
  void on_power_off(bus::Ticks now) override {
    m_powered = false;
    m_station_timer = bus::kNever;
    m_armed = bus::kNever;
    m_station.on_power_off(now);
  }
  void on_frame(const bus::RxFrame& frame) override {
    if (!m_powered) return;
    m_station.on_frame(frame);
    m_model.after_call();
  }
  void on_timer(bus::Ticks now) override {
    if (!m_powered) return;
    m_armed = bus::kNever;  // this wake-up is spent
    if (m_station_timer <= now) {
      m_station_timer = bus::kNever;
      m_station.on_timer(now);
    }
    m_model.m_rs->on_time(now);
    m_model.after_call();
  }
  int receive_filter() const override { return m_station.receive_filter(); }
  const char* kind() const override { return "DP slave (switched)"; }

  void rearm() {
    if (!bound() || !m_powered) return;
    const bus::Ticks at = std::min(m_station_timer, m_model.m_rs->next_deadline());
    if (at == m_armed) return;
    m_armed = at;
    port().set_timer(at);
  }
  bus::DevicePort& outer() { return port(); }
  const bus::DevicePort& outer() const { return port(); }

  SwitchedStationModel& m_model;
  User m_user;
  Port m_port;
  fdl::PassiveStation m_station;
  bus::Ticks m_station_timer = bus::kNever;
  bus::Ticks m_armed = bus::kNever;
  bool m_powered = false;
  bus::Line* m_line = nullptr;
  bus::AttachmentId m_att = -1;
  bool m_off_by_station = false;  ///< powered off by power_off_station(), to bring back
};

bus::Ticks SwitchedStationModel::Port::now() const { return m_if.outer().now(); }
bus::Baud SwitchedStationModel::Port::baud() const { return m_if.outer().baud(); }
void SwitchedStationModel::Port::transmit(bus::Ticks start, std::span<const std::uint8_t> bytes) {
  m_if.outer().transmit(start, bytes);
}
void SwitchedStationModel::Port::set_timer(bus::Ticks at) {
  m_if.m_station_timer = at;
  m_model.rearm_all();
}
bool SwitchedStationModel::Port::receiving() const { return m_if.outer().receiving(); }
void SwitchedStationModel::Port::receive_filter_changed() {
  if (m_if.bound()) m_if.outer().receive_filter_changed();  // unattached: the line reads it later
}

// --- building ---------------------------------------------------------------------------------

SwitchedStationBuild SwitchedStationModel::build(const GsdFile& gsd,
                                                 const std::vector<ModuleChoice>& modules,
                                                 SwitchedStationOptions options) {
  SwitchedStationBuild r;
  const std::string file = std::filesystem::path(gsd.file_name()).filename().string();
  const GsdRedundancy& red = gsd.redundancy();
  const bool flying = options.redundancy.mode == redundancy::RedundancyMode::Flying;
  if (flying) {
    if (!red.flying_redundancy())
      r.errors.push_back(file +
                         " does not declare Flying Redundancy (Slave_Redundancy_supp bit 1)");
    if (options.address > redundancy::kFlyingMaxAddress)
      r.errors.push_back("Flying Redundancy needs a primary address <= 61 (backup = address + "
                         "64), not " + std::to_string(options.address));
  } else if (!red.system_redundancy()) {
    r.errors.push_back(file + " does not declare System Redundancy (Slave_Redundancy_supp bit 0)");
  }
  if (!red.prm_cmd_supp) r.errors.push_back(file + " does not declare PrmCmd_supp = 1");
  if (!gsd.dpv1().dpv1_slave || !gsd.dpv1().prm_block_structure_supp)
    r.errors.push_back(file + " is not a DP-V1 slave with Prm_Block_Structure_supp (the PrmCmd "
                              "block is a structured parameter block)");
  SlaveModelOptions so;
  so.address = options.address;
  so.bus_params = options.bus_params;
  so.tsdr = options.tsdr;
  SlaveSetup s = derive_slave_setup(gsd, modules, so);
  r.errors.insert(r.errors.end(), s.errors.begin(), s.errors.end());
  r.notes = std::move(s.notes);
  if (!r.errors.empty()) return r;

  std::unique_ptr<SwitchedStationModel> m(new SwitchedStationModel());
  try {
    m->m_rs = std::make_unique<redundancy::RedundantSlave>(std::move(s.config), options.redundancy);
  } catch (const std::invalid_argument& e) {
    r.errors.push_back(std::string("unusable configuration: ") + e.what());
    return r;
  }
  m->m_name = options.name.empty()
                  ? gsd.info().model_name + " @" + std::to_string(options.address)
                  : options.name;
  m->m_address = options.address;
  m->m_tsdr = s.tsdr;
  m->m_default_prm = std::move(s.user_prm);
  if (auto ms = red.switch_over_time_ms()) m->m_t_slave_um = bus::Ticks{*ms} * bus::kTicksPerMs;
  SwitchedStationModel* raw = m.get();
  m->m_rs->on_event([raw](const redundancy::RedEvent& e) { raw->m_events.push_back(e); });
  for (int i = 0; i < 2; ++i) m->m_if[i] = std::make_unique<Iface>(*m, i, options.bus_params);
  m->sync_addresses();  // Flying: interface 1 at A + 64
  if (gsd.dpv1().c1_read_write_supp) {  // F3: the modules' parameter records, both interfaces
    m->m_records = std::make_unique<ModuleRecords>(m->m_rs->engine(0).layout().modules.size());
    for (int i = 0; i < 2; ++i) m->m_records->install(m->m_rs->engine(i).application());
  }
  const auto& layout = m->m_rs->engine(0).layout();
  m->m_channels.resize(layout.modules.size());
  m->m_pulled.assign(layout.modules.size(), false);
  std::size_t max_in = 0;
  for (const auto& ml : layout.modules) max_in = std::max(max_in, ml.in_len);
  m->m_scratch.resize(max_in);
  r.model = std::move(m);
  return r;
}

SwitchedStationModel::~SwitchedStationModel() = default;

bus::Device& SwitchedStationModel::interface_device(int i) { return *m_if[i]; }

bus::AttachmentId SwitchedStationModel::attach(int i, bus::Line& line, std::string label) {
  if (label.empty()) label = m_name + (i == 0 ? " A" : " B");
  m_if[i]->m_line = &line;
  m_if[i]->m_att = line.attach(*m_if[i], std::move(label));
  return m_if[i]->m_att;
}

// --- behaviours -------------------------------------------------------------------------------

std::string SwitchedStationModel::set_behaviour(std::size_t module, IoBehaviour b) {
  const auto& layout = m_rs->engine(0).layout();
  if (module >= layout.modules.size()) return "module " + std::to_string(module) + " does not exist";
  const std::size_t len = layout.modules[module].in_len;
  if (len == 0) return "module " + std::to_string(module) + " has no inputs";
  if (std::string e = check_channel_behaviour(layout, module, 0, len, b); !e.empty()) return e;
  m_channels[module].clear();
  m_channels[module].push_back({0, len, std::move(b)});
  return {};
}

std::string SwitchedStationModel::add_channel_behaviour(std::size_t module, std::size_t offset,
                                                        std::size_t width, IoBehaviour b) {
  if (std::string e = check_channel_behaviour(m_rs->engine(0).layout(), module, offset, width, b);
      !e.empty())
    return e;
  m_channels[module].push_back({offset, width, std::move(b)});
  return {};
}

void SwitchedStationModel::refresh_inputs(bus::Ticks now) {
  const auto& layout = m_rs->engine(0).layout();
  dp::SlaveApplication& app = m_rs->engine(0).application();  // both images hold the same inputs
  const std::span<const std::uint8_t> out = m_rs->outputs();
  for (std::size_t m = 0; m < m_channels.size(); ++m) {
    const std::size_t len = layout.modules[m].in_len;
    if (len == 0) continue;
    std::span<std::uint8_t> buf(m_scratch.data(), len);
    if (m_pulled[m]) {  // a pulled module's inputs read 0, its behaviours wait for the plug
      std::fill(buf.begin(), buf.end(), std::uint8_t{0});
      m_rs->write_inputs(m, buf);
      continue;
    }
    if (m_channels[m].empty()) continue;
    app.image().inputs(m).read(buf);
    apply_channel_behaviours(buf, m, m_channels[m], now, m_dp_cycles, [&](std::size_t src) {
      const auto& ml = layout.modules[src];
      return out.subspan(ml.out_offset, ml.out_len);  // the backplane, not an interface's image
    });
    m_rs->write_inputs(m, buf);
  }
}

// --- timers and faults --------------------------------------------------------------------------

void SwitchedStationModel::rearm_all() {
  for (auto& f : m_if)
    if (f) f->rearm();
}

void SwitchedStationModel::sync_addresses() {
  for (int i = 0; i < 2; ++i) {
    if (!m_if[i]) continue;
    const auto a = static_cast<std::uint8_t>(m_address + m_rs->address_offset(i));
    if (m_if[i]->m_station.address() != a) m_if[i]->m_station.set_address(a);
  }
}

std::uint8_t SwitchedStationModel::interface_address(int i) const {
  return m_if[i]->m_station.address();
}

bus::Ticks SwitchedStationModel::now() const {
  for (const auto& f : m_if)
    if (f && f->bound()) return f->outer().now();
  throw std::logic_error("switched station: no interface is attached to a line");
}

void SwitchedStationModel::fail_interface(int i) {
  m_rs->fail_interface(i, now());
  if (m_if[i]->m_line) m_if[i]->m_line->set_transceiver_ok(m_if[i]->m_att, false);
  after_call();
}

void SwitchedStationModel::repair_interface(int i) {
  m_rs->repair_interface(i, now());
  // Repaired while the station is off: the transceiver comes back with power_on_station().
  if (m_if[i]->m_line && m_rs->powered())
    m_if[i]->m_line->set_transceiver_ok(m_if[i]->m_att, true);
  after_call();
}

void SwitchedStationModel::power_off_station() {
  const bus::Ticks t = now();
  m_rs->power_off(t);
  for (auto& f : m_if) {
    // The FDL station goes too (it would still answer FDL Status on its own), whether or not the
    // line knows of the attachment; only an interface the line powers is ours to bring back.
    f->m_off_by_station = f->m_powered;
    if (f->m_powered) f->on_power_off(t);
    if (f->m_line) f->m_line->set_transceiver_ok(f->m_att, false);
  }
  after_call();
}

void SwitchedStationModel::power_on_station() {
  const bus::Ticks t = now();
  for (int i = 0; i < 2; ++i) {
    Iface& f = *m_if[i];
    if (f.m_line && m_rs->role(i) != redundancy::Role::Failed)
      f.m_line->set_transceiver_ok(f.m_att, true);
  }
  for (auto& f : m_if) {
    // As at the line's power-on: the FDL station restarts and powers the RedundantSlave (a cold
    // start, RedundantSlave::power_on) through the interface's port.
    if (!f->m_off_by_station) continue;
    f->m_off_by_station = false;
    f->on_power_on(t);
  }
  if (!m_rs->powered()) m_rs->power_on(t);  // no attachment powered: the backplane still starts
  after_call();
}

std::string SwitchedStationModel::set_module_pulled(std::size_t module, bool pulled) {
  const auto& layout = m_rs->engine(0).layout();
  if (module >= layout.modules.size()) return "module " + std::to_string(module) + " does not exist";
  if (m_pulled[module] == pulled) return {};
  m_pulled[module] = pulled;
  for (int i = 0; i < 2; ++i)
    m_rs->engine(i).application().set_module_state(
        module, pulled ? dp::ModuleState::NoModule : dp::ModuleState::Ok);
  if (m_records) m_records->set_pulled(module, pulled);
  if (pulled && layout.modules[module].in_len > 0) {
    std::span<std::uint8_t> buf(m_scratch.data(), layout.modules[module].in_len);
    std::fill(buf.begin(), buf.end(), std::uint8_t{0});
    m_rs->write_inputs(module, buf);
  }
  // Not enabled (or closed): the Module_Status alone tells the master (OB 83 from the diagnosis).
  (void)raise_alarm(static_cast<std::uint8_t>(pulled ? dp::AlarmType::Pull : dp::AlarmType::Plug),
                    static_cast<std::uint8_t>(module + 1),
                    pulled ? dp::AlarmSpec::Appears : dp::AlarmSpec::Disappears, false);
  return {};
}

dp::AlarmResult SwitchedStationModel::raise_alarm(std::uint8_t type, std::uint8_t slot,
                                                  dp::AlarmSpec spec, bool add_ack,
                                                  std::span<const std::uint8_t> data,
                                                  std::uint8_t* seq_nr) {
  const dp::AlarmResult r = m_rs->raise_alarm(type, slot, spec, add_ack, data, now(), seq_nr);
  after_call();  // raise_alarm ran the station's due timers first: re-arm both lines
  return r;
}

}  // namespace pbvbus::devices
