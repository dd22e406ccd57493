// GsdFile accessors and the assembly of Set_Prm User_Prm_Data and Chk_Cfg data from a module
// selection (protocol-facts.md §I.1, §D.2, §D.3). Decisions: see gsd.hpp.

#include <algorithm>
#include <cctype>
#include <string>

#include "pbvbus/gsd/gsd.hpp"

namespace pbvbus::devices {

namespace {

std::string hex2(std::uint8_t b) {
  static const char* digits = "0123456789ABCDEF";
  std::string s = "0x";
  s += digits[b >> 4];
  s += digits[b & 0x0F];
  return s;
}

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

// Writes one parameter value into its place in the area; bytes outside the buffer are dropped.
void write_value(GsdBytes& buf, std::size_t offset, const GsdExtUserPrmData& def, std::int64_t value) {
  const auto u = static_cast<std::uint64_t>(value);
  switch (def.type) {
    case GsdDataType::Bit:
    case GsdDataType::BitArea: {
      if (offset >= buf.size()) return;
      const unsigned width = static_cast<unsigned>(def.bit_last - def.bit_first + 1);
      const unsigned mask = ((1u << width) - 1u) << def.bit_first;
      const unsigned v = (static_cast<unsigned>(u) << def.bit_first) & mask;
      buf[offset] = static_cast<std::uint8_t>((buf[offset] & ~mask) | v);
      return;
    }
    default: break;
  }
  const std::size_t n = def.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t pos = offset + i;
    if (pos >= buf.size()) return;
    // Big-endian, like every multi-octet PROFIBUS value.
    buf[pos] = static_cast<std::uint8_t>(u >> (8 * (n - 1 - i)));
  }
}

// Builds one area; `settings` are those addressed to this area (already validated).
GsdBytes build_area(const GsdPrmArea& area, const std::map<std::uint16_t, GsdExtUserPrmData>& defs,
                    std::size_t length, const std::vector<const GsdPrmSetting*>& settings = {}) {
  GsdBytes buf(length, 0);
  std::copy_n(area.initial.begin(), std::min(area.initial.size(), length), buf.begin());
  for (const auto& c : area.consts)
    for (std::size_t i = 0; i < c.data.size() && c.offset + i < length; ++i) buf[c.offset + i] = c.data[i];
  for (const auto& r : area.refs) {
    auto it = defs.find(r.ref);
    if (it == defs.end()) continue;
    std::int64_t value = it->second.default_value;
    for (const GsdPrmSetting* s : settings)
      if (s->ref == r.ref && (!s->offset || *s->offset == r.offset)) value = s->value;
    write_value(buf, r.offset, it->second, value);
  }
  return buf;
}

}  // namespace

std::string GsdMessage::to_string() const {
  if (line == 0) return file + ": " + reason;
  return file + ":" + std::to_string(line) + ": " + reason;
}

std::string_view gsd_data_type_name(GsdDataType t) {
  switch (t) {
    case GsdDataType::Bit: return "Bit";
    case GsdDataType::BitArea: return "BitArea";
    case GsdDataType::Unsigned8: return "Unsigned8";
    case GsdDataType::Unsigned16: return "Unsigned16";
    case GsdDataType::Unsigned32: return "Unsigned32";
    case GsdDataType::Signed8: return "Signed8";
    case GsdDataType::Signed16: return "Signed16";
    case GsdDataType::Signed32: return "Signed32";
  }
  return "?";
}

const std::string* GsdPrmText::text_for(std::int64_t value) const {
  for (const auto& [v, t] : texts)
    if (v == value) return &t;
  return nullptr;
}

std::size_t GsdExtUserPrmData::size() const {
  switch (type) {
    case GsdDataType::Unsigned16:
    case GsdDataType::Signed16: return 2;
    case GsdDataType::Unsigned32:
    case GsdDataType::Signed32: return 4;
    default: return 1;
  }
}

bool GsdExtUserPrmData::accepts(std::int64_t v) const {
  if (!allowed.empty()) return std::find(allowed.begin(), allowed.end(), v) != allowed.end();
  return v >= min_value && v <= max_value;
}

std::size_t GsdPrmArea::length(const std::map<std::uint16_t, GsdExtUserPrmData>& defs) const {
  std::size_t len = declared_len ? *declared_len : initial.size();
  for (const auto& c : consts) len = std::max(len, c.offset + c.data.size());
  for (const auto& r : refs) {
    auto it = defs.find(r.ref);
    len = std::max(len, r.offset + (it != defs.end() ? it->second.size() : 1));
  }
  return len;
}

bool GsdFile::supports(bus::Baud b) const { return max_tsdr(b).has_value(); }

std::optional<std::uint16_t> GsdFile::max_tsdr(bus::Baud b) const {
  for (const auto& r : m_baud_rates)
    if (r.baud == b) return r.max_tsdr;
  return std::nullopt;
}

std::optional<std::size_t> GsdFile::find_module(std::string_view name) const {
  for (std::size_t i = 0; i < m_modules.size(); ++i)
    if (m_modules[i].name == name) return i;
  return std::nullopt;
}

std::optional<std::size_t> GsdFile::find_module_by_reference(std::uint32_t reference) const {
  for (std::size_t i = 0; i < m_modules.size(); ++i)
    if (m_modules[i].reference == reference) return i;
  return std::nullopt;
}

const GsdKeyword* GsdFile::keyword(std::string_view name) const {
  for (auto it = m_keywords.rbegin(); it != m_keywords.rend(); ++it)
    if (iequals(it->name, name)) return &*it;
  return nullptr;
}

GsdOutcome<GsdBytes> GsdFile::user_prm_data(const std::vector<std::size_t>& modules) const {
  return user_prm_data(modules, {});
}

GsdOutcome<GsdBytes> GsdFile::user_prm_data(const std::vector<std::size_t>& modules,
                                            const std::vector<GsdPrmSetting>& settings) const {
  GsdOutcome<GsdBytes> out;
  for (std::size_t idx : modules)
    if (idx >= m_modules.size())
      out.errors.push_back("module index " + std::to_string(idx) + " out of range (" +
                           std::to_string(m_modules.size()) + " modules)");
  if (!out.errors.empty()) return out;

  // Settings per area: index 0 = station area; for the n-th selected module, 1 + 2n = its
  // parameter area and 2 + 2n = its F-parameter block.
  std::vector<std::vector<const GsdPrmSetting*>> per_area(2 * modules.size() + 1);
  for (const auto& s : settings) {
    if (s.f_parameter && !s.slot) {
      out.errors.push_back("F-parameter setting without a slot: F-parameters belong to a module");
      continue;
    }
    std::string where = s.slot ? "slot " + std::to_string(*s.slot) : std::string("the station parameters");
    if (s.f_parameter) where = "the F-parameters of " + where;
    if (s.slot && *s.slot >= modules.size()) {
      out.errors.push_back("setting for " + where + ": only " + std::to_string(modules.size()) +
                           " modules selected");
      continue;
    }
    const auto& defs = s.f_parameter ? m_f_defs : m_ext_prm;
    const std::string kind = s.f_parameter ? "F_ExtUserPrmData " : "ExtUserPrmData ";
    auto def = defs.find(s.ref);
    if (def == defs.end()) {
      out.errors.push_back("setting for " + where + ": no " + kind + std::to_string(s.ref));
      continue;
    }
    const std::string what = kind + std::to_string(s.ref) + " '" + def->second.name + "'";
    const GsdPrmArea& area = !s.slot         ? m_global_prm
                             : s.f_parameter ? m_modules[modules[*s.slot]].f.prm
                                             : m_modules[modules[*s.slot]].prm;
    const bool used = std::any_of(area.refs.begin(), area.refs.end(), [&](const GsdPrmRef& r) {
      return r.ref == s.ref && (!s.offset || *s.offset == r.offset);
    });
    if (!used) {
      out.errors.push_back(what + " is not used in " + where +
                           (s.offset ? " at offset " + std::to_string(*s.offset) : std::string()));
      continue;
    }
    if (!def->second.changeable && s.value != def->second.default_value) {
      out.errors.push_back(what + " is not changeable");
      continue;
    }
    if (!def->second.accepts(s.value)) {
      out.errors.push_back(what + ": value " + std::to_string(s.value) + " not allowed");
      continue;
    }
    per_area[s.slot ? 1 + 2 * *s.slot + (s.f_parameter ? 1 : 0) : 0].push_back(&s);
  }
  if (!out.errors.empty()) return out;

  GsdBytes data = build_area(m_global_prm, m_ext_prm, m_global_prm.length(m_ext_prm), per_area[0]);
  if (m_dpv1.dpv1_slave && data.size() < 3) {
    static constexpr std::uint8_t kMinimalDpv1Status[3] = {0x80, 0x00, 0x00};
    for (std::size_t i = data.size(); i < 3; ++i) data.push_back(kMinimalDpv1Status[i]);
    out.notes.push_back("DPV1_Status_1..3 not all given by the file; filled with 80 00 00");
  }
  // Each module: its parameter area, then its F-parameter block (PROFIsafe, gsd.hpp).
  for (std::size_t n = 0; n < modules.size(); ++n) {
    const GsdModule& m = m_modules[modules[n]];
    const GsdBytes part = build_area(m.prm, m_ext_prm, m.prm.length(m_ext_prm), per_area[1 + 2 * n]);
    data.insert(data.end(), part.begin(), part.end());
    const GsdBytes f = build_area(m.f.prm, m_f_defs, m.f.prm.length(m_f_defs), per_area[2 + 2 * n]);
    data.insert(data.end(), f.begin(), f.end());
  }
  if (data.size() > m_max_user_prm_data_len) {
    out.notes.push_back("User_Prm_Data of " + std::to_string(data.size()) +
                        " bytes truncated to Max_User_Prm_Data_Len " +
                        std::to_string(m_max_user_prm_data_len));
    data.resize(m_max_user_prm_data_len);
  }
  out.value = std::move(data);
  return out;
}

GsdBytes GsdFile::prm_area_defaults(const GsdPrmArea& area) const {
  return build_area(area, m_ext_prm, area.length(m_ext_prm));
}

GsdBytes GsdFile::f_prm_defaults(const GsdModule& module) const {
  return build_area(module.f.prm, m_f_defs, module.f.prm.length(m_f_defs));
}

std::size_t GsdFile::module_prm_length(const GsdModule& module) const {
  return module.prm.length(m_ext_prm) + module.f.prm.length(m_f_defs);
}

GsdOutcome<GsdBytes> GsdFile::cfg_data(const std::vector<std::size_t>& modules) const {
  GsdOutcome<GsdBytes> out;
  GsdBytes data;
  for (std::size_t idx : modules) {
    if (idx >= m_modules.size()) {
      out.errors.push_back("module index " + std::to_string(idx) + " out of range (" +
                           std::to_string(m_modules.size()) + " modules)");
      continue;
    }
    const auto& c = m_modules[idx].config;
    data.insert(data.end(), c.begin(), c.end());
  }
  if (out.errors.empty()) out.value = std::move(data);
  return out;
}

std::optional<std::vector<std::size_t>> GsdFile::modules_for_cfg(const GsdBytes& cfg) const {
  // Depth-first over positions; a position from which no split exists is remembered, so the
  // search is linear in cfg.size() x modules.
  std::vector<bool> dead(cfg.size() + 1, false);
  std::vector<std::size_t> chosen;
  auto search = [&](auto& self, std::size_t pos) -> bool {
    if (pos == cfg.size()) return true;
    if (dead[pos]) return false;
    for (std::size_t i = 0; i < m_modules.size(); ++i) {
      const auto& c = m_modules[i].config;
      if (c.empty() || c.size() > cfg.size() - pos || !std::equal(c.begin(), c.end(), cfg.begin() + pos))
        continue;
      chosen.push_back(i);
      if (self(self, pos + c.size())) return true;
      chosen.pop_back();
    }
    dead[pos] = true;
    return false;
  };
  if (!search(search, 0)) return std::nullopt;
  return chosen;
}

GsdOutcome<std::pair<std::size_t, std::size_t>> GsdFile::check_modules(
    const std::vector<std::size_t>& modules) const {
  GsdOutcome<std::pair<std::size_t, std::size_t>> out;
  if (modules.empty()) out.errors.push_back("no module selected");
  std::size_t in = 0;
  std::size_t outp = 0;
  std::size_t cfg_len = 0;
  std::size_t prm_len = m_global_prm.length(m_ext_prm);
  if (m_dpv1.dpv1_slave) prm_len = std::max<std::size_t>(prm_len, 3);
  for (std::size_t idx : modules) {
    if (idx >= m_modules.size()) {
      out.errors.push_back("module index " + std::to_string(idx) + " out of range (" +
                           std::to_string(m_modules.size()) + " modules)");
      continue;
    }
    in += m_modules[idx].input_len;
    outp += m_modules[idx].output_len;
    cfg_len += m_modules[idx].config.size();
    prm_len += module_prm_length(m_modules[idx]);
  }
  if (!m_slave.modular_station && modules.size() > 1)
    out.errors.push_back("a compact station (Modular_Station = 0) takes exactly one module, " +
                         std::to_string(modules.size()) + " selected");
  if (m_slave.modular_station && modules.size() > m_slave.max_module)
    out.errors.push_back(std::to_string(modules.size()) + " modules selected, Max_Module = " +
                         std::to_string(m_slave.max_module));
  if (in > m_slave.max_input_len)
    out.errors.push_back("inputs of " + std::to_string(in) + " bytes exceed Max_Input_Len " +
                         std::to_string(m_slave.max_input_len));
  if (outp > m_slave.max_output_len)
    out.errors.push_back("outputs of " + std::to_string(outp) + " bytes exceed Max_Output_Len " +
                         std::to_string(m_slave.max_output_len));
  if (in + outp > m_slave.max_data_len)
    out.errors.push_back("inputs + outputs of " + std::to_string(in + outp) +
                         " bytes exceed Max_Data_Len " + std::to_string(m_slave.max_data_len));
  // Chk_Cfg carries at most 244 octets of identifiers (§D.3).
  if (cfg_len > 244)
    out.errors.push_back("config data of " + std::to_string(cfg_len) + " bytes exceeds 244");
  if (prm_len > m_max_user_prm_data_len)
    out.errors.push_back("User_Prm_Data of " + std::to_string(prm_len) +
                         " bytes exceeds Max_User_Prm_Data_Len " + std::to_string(m_max_user_prm_data_len));
  if (out.errors.empty()) out.value = std::make_pair(in, outp);
  return out;
}

std::optional<GsdCfgLengths> gsd_cfg_lengths(const GsdBytes& config, std::string* error) {
  GsdCfgLengths r;
  auto fail = [&](std::string why) -> std::optional<GsdCfgLengths> {
    if (error) *error = std::move(why);
    return std::nullopt;
  };
  std::size_t i = 0;
  while (i < config.size()) {
    const std::size_t at = i;
    const std::uint8_t id = config[i++];
    if ((id & 0x30) != 0) {
      // General identifier: bits 3..0 = units - 1, bit 6 = words, bits 5..4 = direction.
      const std::size_t bytes = (static_cast<std::size_t>(id & 0x0F) + 1) * ((id & 0x40) ? 2 : 1);
      if (id & 0x10) r.input_len += bytes;
      if (id & 0x20) r.output_len += bytes;
      if (id & 0x80) r.consistent = true;
      continue;
    }
    // Special identifier: length octets (output first), then manufacturer-specific octets;
    // a count of 15 means "none follow, do not check" (Chk_Cfg semantics).
    const std::size_t lengths = ((id & 0x80) ? 1u : 0u) + ((id & 0x40) ? 1u : 0u);
    const std::size_t manufacturer = (id & 0x0F) == 15 ? 0 : (id & 0x0F);
    if (config.size() - i < lengths + manufacturer)
      return fail("special identifier " + hex2(id) + " at position " + std::to_string(at) +
                  " needs " + std::to_string(lengths + manufacturer) + " more bytes, only " +
                  std::to_string(config.size() - i) + " follow");
    auto take_length = [&](std::size_t& sum) {
      const std::uint8_t b = config[i++];
      sum += (static_cast<std::size_t>(b & 0x3F) + 1) * ((b & 0x40) ? 2 : 1);
      if (b & 0x80) r.consistent = true;
    };
    if (id & 0x80) take_length(r.output_len);
    if (id & 0x40) take_length(r.input_len);
    i += manufacturer;
  }
  return r;
}

}  // namespace pbvbus::devices
