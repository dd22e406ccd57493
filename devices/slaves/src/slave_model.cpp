// A simulated DP slave built from a GSD and a module list (slave_model.hpp).
#include "pbvbus/slaves/slave_model.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <stdexcept>

#include "pbvbus/dp/prm.hpp"
#include "pbvbus/dp/sap.hpp"

namespace pbvbus::devices {

namespace {

/// One Ext_User_Prm_Data_Ref parameter at its place in User_Prm_Data.
struct PrmCheck {
  std::size_t offset = 0;
  GsdExtUserPrmData def;
};

std::int64_t read_parameter(const GsdExtUserPrmData& d, std::span<const std::uint8_t> p) {
  switch (d.type) {
    case GsdDataType::Bit:
    case GsdDataType::BitArea: {
      const unsigned width = static_cast<unsigned>(d.bit_last - d.bit_first + 1);
      return (p[0] >> d.bit_first) & ((1u << width) - 1u);
    }
    case GsdDataType::Unsigned8: return p[0];
    case GsdDataType::Signed8: return static_cast<std::int8_t>(p[0]);
    case GsdDataType::Unsigned16: return (p[0] << 8) | p[1];
    case GsdDataType::Signed16: return static_cast<std::int16_t>(static_cast<std::uint16_t>((p[0] << 8) | p[1]));
    case GsdDataType::Unsigned32:
    case GsdDataType::Signed32: {
      const std::uint32_t u = (static_cast<std::uint32_t>(p[0]) << 24) | (static_cast<std::uint32_t>(p[1]) << 16) |
                              (static_cast<std::uint32_t>(p[2]) << 8) | p[3];
      return d.type == GsdDataType::Unsigned32 ? static_cast<std::int64_t>(u)
                                               : static_cast<std::int64_t>(static_cast<std::int32_t>(u));
    }
  }
  return 0;
}

/// Alarm_Mode n allows this many outstanding alarms in sequence mode (§D.2 DPV1_Status_3).
constexpr std::uint8_t kAlarmModeCount[8] = {1, 2, 4, 8, 12, 16, 24, 32};

/// The GSD's file name without its directory, for messages.
std::string short_name(const GsdFile& gsd) {
  return std::filesystem::path(gsd.file_name()).filename().string();
}

/// The engine-level half of a mutant (the FDL ones map to None here).
dp::EngineMutation engine_mutation(std::optional<SlaveMutant> m) {
  using E = dp::EngineMutation;
  if (!m) return E::None;
  switch (*m) {
    case SlaveMutant::TsdrTooLate:
    case SlaveMutant::IgnoreMinTsdr:
    case SlaveMutant::IgnoreFcb: return E::None;
    case SlaveMutant::NoPrmReqBit: return E::NoPrmReqBit;
    case SlaveMutant::AcceptWrongIdent: return E::AcceptWrongIdent;
    case SlaveMutant::IgnoreWatchdog: return E::IgnoreWatchdog;
    case SlaveMutant::TearConsistent: return E::TearConsistent;
    case SlaveMutant::WrongGetCfg: return E::WrongGetCfg;
    case SlaveMutant::IgnoreClearData: return E::IgnoreClearData;
    case SlaveMutant::IgnoreLock: return E::IgnoreLock;
    case SlaveMutant::AcceptWrongCfg: return E::AcceptWrongCfg;
    case SlaveMutant::IgnoreFreeze: return E::IgnoreFreeze;
    case SlaveMutant::IgnoreSync: return E::IgnoreSync;
    case SlaveMutant::SlowSlaveInterval: return E::SlowSlaveInterval;
    case SlaveMutant::KeepStateOnPowerCycle: return E::KeepStateOnPowerCycle;
    case SlaveMutant::Dpv1BadIndexAccepted: return E::Dpv1BadIndexAccepted;
    case SlaveMutant::RejectFailSafe: return E::RejectFailSafe;
    case SlaveMutant::WrongDiagIdent: return E::WrongDiagIdent;
    case SlaveMutant::GetCfgSapsNotSwapped: return E::GetCfgSapsNotSwapped;
    case SlaveMutant::DataExchangeInWaitCfg: return E::DataExchangeInWaitCfg;
    case SlaveMutant::FcbGlobal: return E::None;
  }
  return E::None;
}

/// The FDL-level half of a mutant; `mutant_tsdr` is the delay tsdr_too_late answers at.
fdl::PassiveMutation passive_mutation(std::optional<SlaveMutant> m, std::uint32_t mutant_tsdr) {
  fdl::PassiveMutation p;
  if (m == SlaveMutant::TsdrTooLate) p.fixed_tsdr = mutant_tsdr;
  if (m == SlaveMutant::IgnoreMinTsdr) p.ignore_min_tsdr = true;
  if (m == SlaveMutant::IgnoreFcb) p.ignore_fcb = true;
  if (m == SlaveMutant::FcbGlobal) p.shared_fcb = true;
  return p;
}

/// tsdr_too_late answers this far beyond the GSD's MaxTsdr.
constexpr std::uint32_t kTooLateMargin = 20;

std::string module_list_text(const GsdFile& gsd) {
  std::string s;
  for (std::size_t i = 0; i < gsd.modules().size(); ++i) {
    if (i > 0) s += ", ";
    s += "#" + std::to_string(i) + " \"" + gsd.modules()[i].name + "\"";
  }
  return s;
}

}  // namespace

// --- the passive station's user: the engine behind input refresh and DP cycle counting ---------

class SlaveModel::User final : public fdl::ResponderUser {
 public:
  explicit User(SlaveModel& m) : m_model(m) {}
  void on_power_on(bus::Ticks now) override { m_model.m_engine->on_power_on(now); }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override {
    dp::SlaveEngine& e = *m_model.m_engine;
    // Data_Exchange = default SAP (no SAPs), unicast, from the owner in Data_Exch.
    const bool dx = !ind.dsap && !ind.ssap && !ind.broadcast() &&
                    (ind.fn == fdl::RequestFn::SrdHigh || ind.fn == fdl::RequestFn::SrdLow) &&
                    e.state() == dp::SlaveState::DataExch && ind.sa == e.master_address();
    m_model.refresh_inputs(ind.now);
    e.on_request(ind, reply);
    if (dx) ++m_model.m_dp_cycles;
  }
  bus::Ticks next_deadline() const override { return m_model.m_engine->next_deadline(); }
  void on_time(bus::Ticks now) override { m_model.m_engine->on_time(now); }

 private:
  SlaveModel& m_model;
};

// --- the passive station's port: timer multiplexing and the mute switch --------------------------

class SlaveModel::Port final : public bus::DevicePort {
 public:
  explicit Port(SlaveModel& m) : m_model(m) {}
  bus::Ticks now() const override { return m_model.port().now(); }
  bus::Baud baud() const override { return m_model.port().baud(); }
  void transmit(bus::Ticks start, std::span<const std::uint8_t> bytes) override {
    if (m_model.m_muted) return;
    m_model.port().transmit(start, bytes);
  }
  void set_timer(bus::Ticks at) override {
    m_model.m_station_timer = at;
    m_model.rearm();
  }
  bool receiving() const override { return m_model.port().receiving(); }
  void receive_filter_changed() override { m_model.port().receive_filter_changed(); }

 private:
  SlaveModel& m_model;
};

// --- building ---------------------------------------------------------------------------------

ModuleChoice ModuleChoice::parse(std::string_view text) {
  if (text.size() > 1 && text[0] == '#' &&
      std::all_of(text.begin() + 1, text.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
      text.size() < 12) {
    return at(static_cast<std::size_t>(std::stoull(std::string(text.substr(1)))));
  }
  return named(std::string(text));
}

GsdOutcome<std::vector<std::size_t>> resolve_modules(const GsdFile& gsd,
                                                     const std::vector<ModuleChoice>& modules) {
  GsdOutcome<std::vector<std::size_t>> out;
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < modules.size(); ++i) {
    const ModuleChoice& c = modules[i];
    const std::string where = "module " + std::to_string(i) + ": ";
    if (c.index) {
      if (*c.index >= gsd.modules().size())
        out.errors.push_back(where + "index #" + std::to_string(*c.index) + " out of range (" +
                             short_name(gsd) + " has " + std::to_string(gsd.modules().size()) +
                             " modules)");
      else
        idx.push_back(*c.index);
      continue;
    }
    if (auto f = gsd.find_module(c.name)) {
      idx.push_back(*f);
    } else {
      out.errors.push_back(where + "unknown module \"" + c.name + "\" (" + short_name(gsd) +
                           " has " + module_list_text(gsd) + ")");
    }
  }
  if (modules.empty()) out.errors.push_back("no modules chosen");
  if (out.errors.empty()) out.value = std::move(idx);
  return out;
}

GsdOutcome<dp::SlaveParams> master_slave_params(const GsdFile& gsd,
                                                const std::vector<ModuleChoice>& modules,
                                                std::uint8_t address,
                                                const std::vector<GsdPrmSetting>& settings) {
  GsdOutcome<dp::SlaveParams> out;
  auto idx = resolve_modules(gsd, modules);
  if (!idx.ok()) {
    out.errors = idx.errors;
    return out;
  }
  auto prm = gsd.user_prm_data(*idx.value, settings);
  out.notes = prm.notes;
  if (!prm.ok()) {
    out.errors = prm.errors;
    return out;
  }
  dp::SlaveParams p;
  p.address = address;
  p.name = gsd.info().model_name;
  p.ident = gsd.ident_number();
  p.user_prm = *prm.value;
  for (std::size_t i : *idx.value) p.modules.push_back({gsd.modules()[i].config, gsd.modules()[i].name});
  p.min_slave_interval = std::max<std::uint16_t>(1, gsd.slave_features().min_slave_intervall);
  p.fail_safe = gsd.slave_features().fail_safe;
  if (gsd.dpv1().c1_response_timeout != 0) p.c1_response_timeout = gsd.dpv1().c1_response_timeout;
  out.value = std::move(p);
  return out;
}

SlaveSetup derive_slave_setup(const GsdFile& gsd, const std::vector<ModuleChoice>& modules,
                              const SlaveModelOptions& options) {
  SlaveSetup r;
  const fdl::BusParams& bp = options.bus_params;
  if (gsd.is_master()) r.errors.push_back(short_name(gsd) + " describes a DP master, not a slave");
  if (options.address > 126)
    r.errors.push_back("address " + std::to_string(options.address) + " out of range 0..126");

  auto idx = resolve_modules(gsd, modules);
  r.errors.insert(r.errors.end(), idx.errors.begin(), idx.errors.end());
  std::vector<std::size_t> chosen = idx.value.value_or(std::vector<std::size_t>{});
  if (idx.ok()) {
    auto chk = gsd.check_modules(chosen);
    r.errors.insert(r.errors.end(), chk.errors.begin(), chk.errors.end());
  }

  const auto max_tsdr = gsd.max_tsdr(bp.baud);
  const bool too_late = options.mutant == SlaveMutant::TsdrTooLate;
  const std::uint32_t tsdr = too_late && max_tsdr ? *max_tsdr + kTooLateMargin
                                                  : options.tsdr.value_or(bp.min_tsdr);
  if (!max_tsdr) {
    std::string sup;
    for (const auto& b : gsd.baud_rates()) sup += (sup.empty() ? "" : ", ") + std::string(bus::baud_name(b.baud));
    r.errors.push_back("baud rate " + std::string(bus::baud_name(bp.baud)) + " is not supported by " +
                       short_name(gsd) + " (supported: " + sup + ")");
  } else {
    if (tsdr < bp.min_tsdr)
      r.errors.push_back("TSDR " + std::to_string(tsdr) + " t_bit is below the min TSDR " +
                         std::to_string(bp.min_tsdr) + " t_bit");
    if (tsdr > *max_tsdr && !too_late)  // the mutant bypasses exactly this bound
      r.errors.push_back("TSDR " + std::to_string(tsdr) + " t_bit is above the GSD's MaxTsdr_" +
                         std::string(bus::baud_name(bp.baud)) + " = " + std::to_string(*max_tsdr) +
                         " t_bit");
  }

  GsdBytes prm;
  if (idx.ok()) {
    auto p = gsd.user_prm_data(chosen);
    r.errors.insert(r.errors.end(), p.errors.begin(), p.errors.end());
    r.notes = p.notes;
    if (p.value) prm = *p.value;
  }
  if (!r.errors.empty()) return r;

  // --- the slave's configuration -----------------------------------------------------------
  const GsdSlaveFeatures& sf = gsd.slave_features();
  const GsdDpv1Features& v1 = gsd.dpv1();
  dp::SlaveConfig cfg;
  cfg.ident = gsd.ident_number();
  cfg.features.sync = sf.sync_mode_supp;
  cfg.features.freeze = sf.freeze_mode_supp;
  cfg.features.fail_safe = sf.fail_safe;
  cfg.features.set_slave_add = sf.set_slave_add_supp;
  cfg.features.dpv1 = v1.dpv1_slave;
  cfg.features.c1_read_write = v1.dpv1_slave && v1.c1_read_write_supp;
  cfg.features.c2 = v1.dpv1_slave && v1.c2_read_write_supp;
  cfg.features.c2_connections = std::max<std::uint8_t>(1, v1.c2_max_count_channels);
  if (v1.dpv1_slave) {
    std::uint8_t al = 0;
    if (v1.diagnostic_alarm_supp) al |= dp::kEnableDiagnosticAlarm;
    if (v1.process_alarm_supp) al |= dp::kEnableProcessAlarm;
    if (v1.pull_plug_alarm_supp) al |= dp::kEnablePullPlugAlarm;
    if (v1.status_alarm_supp) al |= dp::kEnableStatusAlarm;
    if (v1.update_alarm_supp) al |= dp::kEnableUpdateAlarm;
    if (v1.manufacturer_specific_alarm_supp) al |= dp::kEnableManufacturerAlarm;
    cfg.features.alarms_supported = al;
    std::uint8_t mode = 0;
    for (std::uint8_t m = 1; m < 8; ++m)
      if (kAlarmModeCount[m] <= v1.alarm_sequence_mode_count) mode = m;
    cfg.features.max_alarm_mode = mode;
    cfg.features.wd_base_1ms = v1.wd_base_1ms_supp;
    cfg.features.check_cfg_mode = v1.check_cfg_mode;
    cfg.features.prm_structure = v1.prm_block_structure_supp;
    cfg.features.prm_cmd = gsd.redundancy().prm_cmd_supp;
  }
  cfg.min_user_prm_len = prm.size();
  // Structured parameter blocks follow the GSD part when the slave accepts them.
  cfg.max_user_prm_len = cfg.features.prm_structure ? dp::kMaxUserPrmLen : prm.size();

  // Every Ext_User_Prm_Data_Ref parameter at its place: station area, then per module its area
  // and its PROFIsafe F-parameter block (F_Ext_User_Prm_Data_Ref).
  std::vector<PrmCheck> checks;
  const auto& defs = gsd.ext_user_prm_data();
  auto add_area = [&](const GsdPrmArea& area, const std::map<std::uint16_t, GsdExtUserPrmData>& area_defs,
                      std::size_t base) {
    for (const auto& ref : area.refs) {
      auto it = area_defs.find(ref.ref);
      if (it != area_defs.end()) checks.push_back({base + ref.offset, it->second});
    }
  };
  std::size_t base = 0;
  add_area(gsd.global_prm(), defs, 0);
  base = gsd.global_prm().length(defs);
  if (v1.dpv1_slave) base = std::max<std::size_t>(base, 3);
  for (std::size_t i : chosen) {
    const GsdModule& m = gsd.modules()[i];
    add_area(m.prm, defs, base);
    add_area(m.f.prm, gsd.f_prm_defs(), base + m.prm.length(defs));
    base += gsd.module_prm_length(m);
  }
  cfg.check_user_prm = [checks = std::move(checks)](std::span<const std::uint8_t> data) {
    for (const auto& c : checks) {
      if (c.offset + c.def.size() > data.size()) continue;  // cut by Max_User_Prm_Data_Len
      if (!c.def.accepts(read_parameter(c.def, data.subspan(c.offset)))) return false;
    }
    return true;
  };
  for (std::size_t i : chosen) cfg.modules.push_back({gsd.modules()[i].config, gsd.modules()[i].name});
  cfg.min_slave_interval = std::max<std::uint16_t>(1, sf.min_slave_intervall);
  cfg.max_diag_len = std::clamp<std::size_t>(sf.max_diag_data_len, dp::kStdDiagLen, dp::kMaxDiagLen);
  cfg.mutation = engine_mutation(options.mutant);
  r.modules = std::move(chosen);
  r.user_prm = std::move(prm);
  r.tsdr = tsdr;
  r.config = std::move(cfg);
  return r;
}

SlaveModelBuild SlaveModel::build(const GsdFile& gsd, const std::vector<ModuleChoice>& modules,
                                  SlaveModelOptions options) {
  SlaveModelBuild r;
  SlaveSetup s = derive_slave_setup(gsd, modules, options);
  r.errors = std::move(s.errors);
  r.notes = std::move(s.notes);
  if (!r.errors.empty()) return r;
  const fdl::BusParams& bp = options.bus_params;
  const GsdDpv1Features& v1 = gsd.dpv1();
  const std::uint32_t tsdr = s.tsdr;
  const std::vector<std::size_t>& chosen = s.modules;
  dp::SlaveConfig cfg = std::move(s.config);
  GsdBytes prm = std::move(s.user_prm);

  std::unique_ptr<SlaveModel> m(new SlaveModel());
  try {
    m->m_engine = std::make_unique<dp::SlaveEngine>(std::move(cfg));
  } catch (const std::invalid_argument& e) {
    r.errors.push_back(std::string("unusable configuration: ") + e.what());
    return r;
  }
  m->m_name = options.name.empty()
                  ? gsd.info().model_name + " @" + std::to_string(options.address)
                  : options.name;
  m->m_tsdr = tsdr;
  m->m_default_prm = std::move(prm);
  m->m_dpv1 = v1.dpv1_slave;
  m->m_dpv1_pull_plug = v1.dpv1_slave && v1.pull_plug_alarm_supp;
  if (v1.dpv1_slave && v1.c1_read_write_supp) {  // F3: the modules' parameter records
    m->m_records = std::make_unique<ModuleRecords>(chosen.size());
    m->m_records->install(m->m_engine->application());
  }
  m->m_user = std::make_unique<User>(*m);
  m->m_port = std::make_unique<Port>(*m);
  m->m_station = std::make_unique<fdl::PassiveStation>(options.address, bp, *m->m_user, tsdr);
  m->m_station->bind(*m->m_port);
  m->m_mutant = options.mutant;
  if (options.mutant) m->m_station->set_mutation(passive_mutation(options.mutant, tsdr));
  std::size_t max_in = 0, max_out = 0;
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    Module mod;
    mod.gsd_index = chosen[k];
    m->m_modules.push_back(std::move(mod));
    max_in = std::max(max_in, m->m_engine->layout().modules[k].in_len);
    max_out = std::max(max_out, m->m_engine->layout().modules[k].out_len);
  }
  m->m_scratch.resize(max_in);
  m->m_out_scratch.resize(max_out);
  r.model = std::move(m);
  return r;
}

SlaveModel::~SlaveModel() = default;

// --- behaviours ---------------------------------------------------------------------------------

std::string SlaveModel::set_behaviour(std::size_t module, IoBehaviour b) {
  if (module >= m_modules.size()) return "module " + std::to_string(module) + " does not exist";
  const std::size_t len = m_engine->layout().modules[module].in_len;
  if (len == 0) return "module " + std::to_string(module) + " has no inputs";
  std::vector<ChannelBehaviour> keep;
  keep.swap(m_modules[module].channels);
  std::string err = add_channel_behaviour(module, 0, len, std::move(b));
  if (!err.empty()) keep.swap(m_modules[module].channels);
  return err;
}

std::string check_channel_behaviour(const dp::SlaveLayout& layout, std::size_t module,
                                    std::size_t offset, std::size_t width, const IoBehaviour& b) {
  if (module >= layout.modules.size()) return "module " + std::to_string(module) + " does not exist";
  const std::size_t len = layout.modules[module].in_len;
  if (width == 0 || offset + width > len)
    return "module " + std::to_string(module) + ": channel octets " + std::to_string(offset) + "+" +
           std::to_string(width) + " outside its " + std::to_string(len) + " input octets";
  if (std::string e = check_behaviour(b, layout.modules.size()); !e.empty())
    return "module " + std::to_string(module) + ": " + e;
  if (b.kind == IoBehaviour::Kind::Echo) {
    const std::size_t src = b.source_module.value_or(module);
    if (layout.modules[src].out_len == 0)
      return "module " + std::to_string(module) + ": echo source module " + std::to_string(src) +
             " has no outputs";
  }
  return {};
}

void apply_channel_behaviours(std::span<std::uint8_t> buf, std::size_t module,
                              const std::vector<ChannelBehaviour>& channels, bus::Ticks now,
                              std::uint64_t cycles, const EchoSource& outputs) {
  for (const ChannelBehaviour& c : channels) {
    auto dst = buf.begin() + static_cast<std::ptrdiff_t>(c.offset);
    const IoBehaviour& b = c.behaviour;
    switch (b.kind) {
      case IoBehaviour::Kind::Constant:
        for (std::size_t i = 0; i < c.width; ++i)
          dst[static_cast<std::ptrdiff_t>(i)] = i < b.constant.size() ? b.constant[i] : 0;
        break;
      case IoBehaviour::Kind::Echo: {
        const std::span<const std::uint8_t> ob = outputs(b.source_module.value_or(module));
        for (std::size_t i = 0; i < c.width; ++i)
          dst[static_cast<std::ptrdiff_t>(i)] = i < ob.size() ? ob[i] : 0;
        break;
      }
      default: {
        auto u = static_cast<std::uint64_t>(behaviour_value(b, now, cycles));
        for (std::size_t i = c.width; i-- > 0;) {  // as put_big_endian()
          dst[static_cast<std::ptrdiff_t>(i)] = static_cast<std::uint8_t>(u & 0xFF);
          u >>= 8;
        }
        break;
      }
    }
  }
}

std::string SlaveModel::add_channel_behaviour(std::size_t module, std::size_t offset, std::size_t width,
                                              IoBehaviour b) {
  if (std::string e = check_channel_behaviour(m_engine->layout(), module, offset, width, b); !e.empty())
    return e;
  m_modules[module].channels.push_back({offset, width, std::move(b)});
  return {};
}

void SlaveModel::refresh_inputs(bus::Ticks now) {
  dp::SlaveApplication& app = m_engine->application();
  for (std::size_t m = 0; m < m_modules.size(); ++m) {
    Module& mod = m_modules[m];
    const std::size_t len = app.module(m).in_len;
    if (len == 0 || (mod.channels.empty() && !mod.pulled && !m_stopped)) continue;
    std::span<std::uint8_t> buf(m_scratch.data(), len);
    if (mod.pulled || m_stopped) {
      std::fill(buf.begin(), buf.end(), std::uint8_t{0});
    } else {
      app.image().inputs(m).read(buf);
      apply_channel_behaviours(buf, m, mod.channels, now, m_dp_cycles, [&](std::size_t src) {
        std::span<std::uint8_t> ob(m_out_scratch.data(), app.module(src).out_len);
        app.read_outputs(src, ob);
        return std::span<const std::uint8_t>(ob);
      });
    }
    app.write_inputs(m, buf);
  }
}

// --- faults -------------------------------------------------------------------------------------

std::string SlaveModel::check_fault(const SlaveFault& f) const {
  using K = SlaveFault::Kind;
  if (f.kind == K::Mute || f.kind == K::Unmute || f.kind == K::SlaveStop || f.kind == K::SlaveRun)
    return {};
  if (f.module >= m_modules.size())
    return std::string(to_string(f.kind)) + ": module " + std::to_string(f.module) +
           " does not exist (" + std::to_string(m_modules.size()) + " modules)";
  if (f.kind == K::ChannelDiagAppears || f.kind == K::ChannelDiagDisappears) {
    if (f.channel > 63) return "channel diagnosis: channel " + std::to_string(f.channel) + " > 63";
    if (f.error == 0 || f.error > 31)
      return "channel diagnosis: error type " + std::to_string(f.error) + " outside 1..31";
    if (m_engine->layout().modules[f.module].first_id > 63)
      return "channel diagnosis: module " + std::to_string(f.module) + " has identifier number > 63";
  }
  if (f.kind == K::ProcessAlarm) {
    if (!m_dpv1) return "process alarm: the slave is not DP-V1";
    if (f.data.size() > 59) return "process alarm: more than 59 octets of data";
  }
  return {};
}

std::string SlaveModel::apply(const SlaveFault& f) {
  if (std::string e = check_fault(f); !e.empty()) return e;
  do_apply(f);
  return {};
}

std::string SlaveModel::schedule(bus::Ticks at, SlaveFault f) {
  if (std::string e = check_fault(f); !e.empty()) return e;
  Scheduled s{at, m_fault_order++, std::move(f)};
  auto pos = std::upper_bound(m_faults.begin(), m_faults.end(), s, [](const Scheduled& a, const Scheduled& b) {
    return a.at != b.at ? a.at < b.at : a.order < b.order;
  });
  m_faults.insert(pos, std::move(s));
  if (m_powered) rearm();
  return {};
}

void SlaveModel::do_apply(const SlaveFault& f) {
  using K = SlaveFault::Kind;
  dp::SlaveApplication& app = m_engine->application();
  const auto slot = static_cast<std::uint8_t>(f.module + 1);
  switch (f.kind) {
    case K::Mute: m_muted = true; break;
    case K::Unmute: m_muted = false; break;
    case K::ChannelDiagAppears:
    case K::ChannelDiagDisappears: {
      dp::ChannelDiag c;
      c.module = static_cast<std::uint8_t>(m_engine->layout().modules[f.module].first_id);
      c.channel = f.channel;
      c.direction = f.direction;
      c.type = f.type;
      c.error = f.error;
      const bool appears = f.kind == K::ChannelDiagAppears;
      if (appears)
        app.add_channel_diag(c);
      else
        app.remove_channel_diag(c);
      if (f.alarm && m_dpv1) {
        const auto bytes = c.encode();
        app.raise_alarm(static_cast<std::uint8_t>(dp::AlarmType::Diagnostic), slot,
                        appears ? dp::AlarmSpec::Appears : dp::AlarmSpec::Disappears, false, bytes);
      }
      break;
    }
    case K::ModulePulled:
    case K::ModulePlugged: {
      const bool pulled = f.kind == K::ModulePulled;
      if (m_modules[f.module].pulled == pulled) break;
      m_modules[f.module].pulled = pulled;
      app.set_module_state(f.module, pulled ? dp::ModuleState::NoModule : dp::ModuleState::Ok);
      if (m_records) m_records->set_pulled(f.module, pulled);
      if (pulled && bound()) refresh_inputs(port().now());  // zero now, not at the next request
      if (m_dpv1_pull_plug)
        app.raise_alarm(static_cast<std::uint8_t>(pulled ? dp::AlarmType::Pull : dp::AlarmType::Plug), slot,
                        pulled ? dp::AlarmSpec::Appears : dp::AlarmSpec::Disappears, false);
      break;
    }
    case K::SlaveStop:
    case K::SlaveRun: {
      const bool stop = f.kind == K::SlaveStop;
      if (m_stopped == stop) break;
      m_stopped = stop;
      const std::array<std::uint8_t, 4> rec0{kS7Rec0ModuleFault, 0x00, kS7Rec0MdlStop, 0x00};
      if (m_dpv1) {
        if (stop)
          app.set_status(kStatusMessage, 0, static_cast<std::uint8_t>(dp::AlarmSpec::Appears),
                         rec0);
        else
          app.clear_status(kStatusMessage, 0);
      } else {
        app.set_device_diag(stop ? std::span<const std::uint8_t>(rec0)
                                 : std::span<const std::uint8_t>{});
      }
      app.set_ext_diag(stop);
      if (bound()) refresh_inputs(port().now());  // zero now, not at the next request
      break;
    }
    case K::ProcessAlarm:
      app.raise_alarm(static_cast<std::uint8_t>(dp::AlarmType::Process), slot, dp::AlarmSpec::None, false,
                      f.data);
      break;
  }
}

void SlaveModel::run_due(bus::Ticks now) {
  while (!m_faults.empty() && m_faults.front().at <= now) {
    SlaveFault f = std::move(m_faults.front().fault);
    m_faults.erase(m_faults.begin());
    do_apply(f);
  }
}

void SlaveModel::rearm() {
  bus::Ticks at = m_station_timer;
  if (!m_faults.empty()) at = std::min(at, m_faults.front().at);
  if (!bound() || !m_powered) return;
  m_armed = at;
  port().set_timer(at);
}

// --- bus::Device ---------------------------------------------------------------------------------

void SlaveModel::on_power_on(bus::Ticks now) {
  m_powered = true;
  m_station_timer = bus::kNever;
  run_due(now);
  m_station->on_power_on(now);  // arms the station's timer through Port::set_timer
  rearm();
}

void SlaveModel::on_power_off(bus::Ticks now) {
  m_powered = false;
  m_station_timer = bus::kNever;
  m_armed = bus::kNever;
  m_station->on_power_off(now);
}

void SlaveModel::on_frame(const bus::RxFrame& frame) {
  if (!m_powered) return;
  run_due(frame.end);
  if (m_muted) return;  // deaf: the passive station never hears it
  m_station->on_frame(frame);
  rearm();
}

void SlaveModel::on_timer(bus::Ticks now) {
  if (!m_powered) return;
  run_due(now);
  if (m_station_timer <= now) {
    m_station_timer = bus::kNever;
    m_station->on_timer(now);  // re-requests its timer if it still needs one
  }
  rearm();
}

}  // namespace pbvbus::devices
