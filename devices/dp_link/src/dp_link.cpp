// An IM 157 link: switched station above, DP master below (dp_link.hpp, docs/dp-link.md).
#include "pbvbus/dp_link/dp_link.hpp"

#include <algorithm>
#include <stdexcept>

namespace pbvbus::devices {

/// The coupler's master on the lower line: the dp::Master behind its ActiveStation, with the
/// link's copies around the calls the station makes into it.
class DpLink::Node final : public fdl::InitiatorUser {
 public:
  Node(DpLink& l, const dp::MasterParams& mp, std::vector<dp::SlaveParams> slaves,
       const fdl::BusParams& bp)
      : m_link(l), m_master(mp, std::move(slaves)), m_station(mp.address, bp, *this) {}

  void on_power_on(bus::Ticks now) override { m_master.on_power_on(now); }
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override {
    return m_master.next_request(prio, now, out);
  }
  void on_confirmation(const fdl::Confirmation& con) override {
    m_master.on_confirmation(con);
    m_link.copy_inputs();
  }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override {
    m_master.on_request(ind, reply);
  }
  void on_token(bus::Ticks now, bus::Ticks trr) override {
    m_link.copy_outputs();  // the backplane as it is now, before the pass is built
    m_master.on_token(now, trr);
  }
  void on_observed(bus::Ticks now, const fdl::Telegram& t) override { m_master.on_observed(now, t); }

  DpLink& m_link;
  dp::Master m_master;
  fdl::ActiveStation m_station;
};

std::string check_lower_baud(DpLinkKind kind, bus::Baud baud) {
  if (kind == DpLinkKind::DpPaLink)
    return baud == bus::Baud::k31_25 ? std::string()
                                     : "a DP/PA link's lower line (PROFIBUS PA, MBP) runs at "
                                       "31.25 kbit/s only";
  if (baud < bus::Baud::k187_5 || baud > bus::Baud::k1_5M)
    return "a Y-link's lower DP line runs at 187.5 kbit/s to 1.5 Mbit/s";
  return {};
}

DpLinkBuild DpLink::build(DpLinkOptions o, std::vector<dp::SlaveParams> lower) {
  DpLinkBuild r;
  if (std::string e = check_lower_baud(o.kind, o.lower_bus_params.baud); !e.empty())
    r.errors.push_back(e);
  if (lower.empty()) r.errors.push_back(std::string(to_string(o.kind)) + " without lower stations");
  if (lower.size() > kLinkMaxLowerStations)
    r.errors.push_back(std::to_string(lower.size()) + " lower stations, at most " +
                       std::to_string(kLinkMaxLowerStations));
  if (!r.errors.empty()) return r;

  std::vector<LinkGsdModule> mods;
  for (const dp::SlaveParams& p : lower) {
    LinkGsdModule m;
    m.name = (p.name.empty() ? std::string("station") : p.name) + " @" + std::to_string(p.address);
    m.cfg = p.chk_cfg_du();
    mods.push_back(std::move(m));
  }
  const std::string text = link_gsd_text(o.kind, mods, o.switchover);
  GsdParseResult g = parse_gsd(text, o.kind == DpLinkKind::YLink ? "PBVB0A57.gsd" : "PBVB0A58.gsd");
  if (!g.ok()) {
    for (const auto& e : g.errors) r.errors.push_back("link GSD: " + e.to_string());
    return r;
  }
  std::unique_ptr<DpLink> l(new DpLink());
  l->m_kind = o.kind;
  l->m_switchover = o.switchover;
  l->m_gsd = std::make_unique<GsdFile>(std::move(*g.file));
  for (std::size_t i = 0; i < lower.size(); ++i) l->m_choices.push_back(ModuleChoice::at(i));
  l->m_name = o.name.empty() ? std::string(to_string(o.kind)) + " @" + std::to_string(o.address)
                             : o.name;
  SwitchedStationOptions so;
  so.address = o.address;
  so.bus_params = o.upper_bus_params;
  so.name = l->m_name;
  so.redundancy = o.redundancy;
  if (o.switchover > 0) {
    // The coupler's own switchover time: a commanded switchover crosses the internal link twice
    // (switchover request, take-over; redundant_slave.hpp), so each crossing takes half of it.
    redundancy::RedundantSlaveParams& rp = so.redundancy;
    rp.link_delay = std::max<bus::Ticks>(1, o.switchover / 2);
    rp.switch_timeout = 2 * rp.link_delay + 10 * bus::kTicksPerMs;
    rp.supervision = std::max(rp.supervision, rp.heartbeat_period + 2 * rp.link_delay +
                                                  100 * bus::kTicksPerMs);
  }
  SwitchedStationBuild sb = SwitchedStationModel::build(*l->m_gsd, l->m_choices, so);
  if (!sb.ok()) {
    r.errors = std::move(sb.errors);
    return r;
  }
  l->m_upper = std::move(sb.model);
  for (const dp::SlaveParams& p : lower) l->m_lower.push_back(p.address);
  dp::MasterParams mp;
  mp.address = o.lower_master_address;
  try {
    l->m_node = std::make_unique<Node>(*l, mp, std::move(lower), o.lower_bus_params);
  } catch (const std::invalid_argument& e) {
    r.errors.push_back(std::string("lower master: ") + e.what());
    return r;
  }
  l->m_in_gen.assign(l->m_lower.size(), 0);
  l->m_missing.assign(l->m_lower.size(), false);
  DpLink* raw = l.get();
  l->m_node->m_master.set_event_handler([raw](const dp::MasterEvent& e) { raw->on_lower_event(e); });
  r.link = std::move(l);
  return r;
}

DpLink::~DpLink() = default;

dp::Master& DpLink::lower_master() { return m_node->m_master; }
const dp::Master& DpLink::lower_master() const { return m_node->m_master; }
fdl::ActiveStation& DpLink::lower_station() { return m_node->m_station; }

dp::SlaveParams DpLink::upper_slave_params() const {
  auto sp = master_slave_params(*m_gsd, m_choices, m_upper->address());
  if (!sp.ok()) throw std::logic_error("link GSD: no master configuration");
  dp::SlaveParams p = *sp.value;
  p.name = m_name;
  p.prm_cmd.assign(8, 0);  // the redundant master system writes the block
  return p;
}

bus::AttachmentId DpLink::attach_upper(int i, bus::Line& line, std::string label) {
  return m_upper->attach(i, line, std::move(label));
}

bus::AttachmentId DpLink::attach_lower(bus::Line& line, std::string label) {
  if (label.empty()) label = m_name + " master";
  return line.attach(m_node->m_station, std::move(label));
}

std::optional<std::size_t> DpLink::module_of(std::uint8_t a) const {
  const auto it = std::find(m_lower.begin(), m_lower.end(), a);
  if (it == m_lower.end()) return std::nullopt;
  return static_cast<std::size_t>(it - m_lower.begin());
}

bool DpLink::lower_failed(std::uint8_t a) const {
  const auto m = module_of(a);
  return m && m_missing[*m];
}

void DpLink::copy_outputs() {
  const auto& layout = m_upper->redundant_slave().engine(0).layout().modules;
  const std::span<const std::uint8_t> out = m_upper->outputs();
  dp::Master& master = m_node->m_master;
  for (std::size_t m = 0; m < m_lower.size(); ++m) {
    const dp::ModuleLayout& ul = layout[m];
    if (ul.out_len == 0) continue;
    dp::MasterImage& img = master.image(m_lower[m]);
    for (std::size_t k = 0; k < img.modules(); ++k) {
      const dp::ModuleLayout& ll = img.module(k);
      if (ll.out_len == 0) continue;
      img.write_outputs(k, out.subspan(ul.out_offset + ll.out_offset, ll.out_len));
    }
  }
}

void DpLink::copy_inputs() {
  const dp::Master& master = m_node->m_master;
  for (std::size_t m = 0; m < m_lower.size(); ++m) {
    const dp::MasterImage& img = master.image(m_lower[m]);
    if (img.input_length() == 0 || m_missing[m]) continue;
    const std::uint32_t gen = img.inputs_generation();
    if (gen == m_in_gen[m]) continue;
    m_in_gen[m] = gen;
    m_buf.resize(img.input_length());
    if (img.read_all_inputs(m_buf) == dp::ImageAccess::Ok)
      m_upper->redundant_slave().write_inputs(m, m_buf);
  }
}

void DpLink::set_module_missing(std::size_t m, bool missing) {
  if (m_missing[m] == missing) return;
  m_missing[m] = missing;
  redundancy::RedundantSlave& rs = m_upper->redundant_slave();
  for (int i = 0; i < 2; ++i)
    rs.engine(i).application().set_module_state(
        m, missing ? dp::ModuleState::NoModule : dp::ModuleState::Ok);
  const std::size_t in_len = m_upper->redundant_slave().engine(0).layout().modules[m].in_len;
  if (missing && in_len > 0) {
    m_buf.assign(in_len, 0);  // a missing station's inputs read 0
    rs.write_inputs(m, m_buf);
  }
  if (!missing) m_in_gen[m] = m_node->m_master.image(m_lower[m]).inputs_generation() - 1;
}

void DpLink::on_lower_event(const dp::MasterEvent& e) {
  if (const auto m = module_of(e.slave)) {
    if (e.kind == dp::MasterEvent::Kind::StationFailure) set_module_missing(*m, true);
    if (e.kind == dp::MasterEvent::Kind::DataExchangeEntered) set_module_missing(*m, false);
  }
  if (m_lower_events) m_lower_events(e);
}

}  // namespace pbvbus::devices
