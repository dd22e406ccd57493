// What the real S7-400H refuses (h_config_rules.hpp; docs/h-config-rules.md).
#include "pbvbus/scenario/h_config_rules.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <tuple>

#include "pbvbus/dp/cfg_identifier.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

const HCpuLimits& h_cpu_limits(scenario::HCpuPair::CpuType type) {
  // 001 §13.1 (414-4H): X1 max. 32 slaves L12001, X2 max. 96 L12054, process image 8 KB/8 KB
  // settable L11664-11665, default 256/256 L11666. §13.2 (417-4H): X1 32 L12762, X2 125
  // L12816, 16 KB/16 KB L12405, default 1024/1024 L12407.
  static const HCpuLimits k414{"CPU 414-4H", 32, 96, 8192, 256, "S7-400H manual 001 L12001, L12054",
                               "S7-400H manual 001 L11664-11666"};
  static const HCpuLimits k417{"CPU 417-4H", 32, 125, 16384, 1024, "S7-400H manual 001 L12762, L12816; 000 L1724",
                               "S7-400H manual 001 L12405-12407"};
  return type == scenario::HCpuPair::CPU_414_4H ? k414 : k417;
}

HProcessImageSize h_process_image_size(const scenario::HCpuPair& cpu) {
  const HCpuLimits& l = h_cpu_limits(cpu.cpu_type());
  return {cpu.has_input_bytes() ? cpu.input_bytes() : l.process_image_default,
          cpu.has_output_bytes() ? cpu.output_bytes() : l.process_image_default};
}

namespace {

using Place = scenario::HMasterPlace;

const char* interface_name(Place::Interface i) {
  switch (i) {
    case Place::X1_MPI_DP: return "X1 (MPI/DP)";
    case Place::CP_443_5_EXT: return "CP 443-5 Extended";
    default: return "X2 (DP)";
  }
}

/// One master's place after the defaults.
struct MasterPlace {
  unsigned rack = 0;
  Place::Interface interface = Place::X2_DP;
  std::optional<unsigned> slot;  ///< none: a CP without a slot (an error already)
  std::string str() const {
    std::string s = "rack " + std::to_string(rack) + " " + interface_name(interface);
    if (slot) s += " in slot " + std::to_string(*slot);
    return s;
  }
};

class RuleChecker {
 public:
  RuleChecker(const ScenarioPlan& plan, const DpLocator& locate, const HLocator& hlocate,
              std::vector<Diagnostic>& errors)
      : m_plan(plan), m_locate(locate), m_hlocate(hlocate), m_errors(errors) {}

  void run() {
    // Each redundant system named by an h_system, once: the CPU type of the first h_system
    // with a cpu part that names it (default 417-4H).
    std::map<int, std::size_t> owner;  // system -> h_systems index
    for (std::size_t k = 0; k < m_plan.h_systems.size(); ++k) {
      const auto& hp = m_plan.h_systems[k];
      check_h_system(hp);
      for (const auto& d : hp.dp_systems) {
        if (d.system < 0) continue;
        auto it = owner.find(d.system);
        if (it == owner.end())
          owner.emplace(d.system, k);
        else if (!has_cpu(m_plan.h_systems[it->second]) && has_cpu(hp))
          it->second = k;
      }
    }
    for (auto [s, k] : owner) check_system(s, m_plan.h_systems[k]);
    for (std::size_t k = 0; k < m_plan.h_systems.size(); ++k) check_places(m_plan.h_systems[k]);
  }

 private:
  bool has_cpu(const HSystemPlan& hp) const { return m_plan.proto.h_system(hp.source).has_cpu(); }
  const scenario::HCpuPair& cpu(const HSystemPlan& hp) const { return m_plan.proto.h_system(hp.source).cpu(); }

  void error_at(std::pair<int, int> at, std::string msg) {
    m_errors.push_back({m_plan.file, at.first, at.second, std::move(msg)});
  }

  // ---- per h_system: D5 (12 master systems), C4 (process image) ----
  void check_h_system(const HSystemPlan& hp) {
    const auto& h = m_plan.proto.h_system(hp.source);
    if (static_cast<std::size_t>(h.dp_system_size()) > kMaxHDpSystems)
      error_at(m_locate("h_system", hp.source, "dp_system", static_cast<int>(kMaxHDpSystems)),
               "h_system \"" + hp.name + "\": " + std::to_string(h.dp_system_size()) +
                   " DP master systems; an H-system has at most 12 per subsystem (2 on the CPU's "
                   "interfaces + 10 CP 443-5 Extended) (S7-400H manual 000 L1722, D5)");
    if (!h.has_cpu()) return;
    check_dp_sfcs(hp);
    const auto& c = h.cpu();
    const HCpuLimits& lim = h_cpu_limits(c.cpu_type());
    const HProcessImageSize pi = h_process_image_size(c);
    bool sizes_ok = true;
    for (auto [n, field, what] : {std::tuple{pi.inputs, "input_bytes", "inputs"},
                                  std::tuple{pi.outputs, "output_bytes", "outputs"}})
      if (n > lim.process_image_max) {
        error_at(m_hlocate(hp.source, {{"cpu"}, {field}}),
                 "h_system \"" + hp.name + "\": a process image of " + std::to_string(n) + " octets of " +
                     what + " is more than a " + lim.name + " has (" + std::to_string(lim.process_image_max) +
                     " octets; " + lim.pi_source + ", C4)");
        sizes_ok = false;
      }
    if (sizes_ok && hp.runtime) check_process_image(hp, pi);
  }

  // ---- D4: SFC 11 DPSYC_FR and SFC 12 D_ACT_DP in the program (docs/h-dp-sfc.md) ----
  void check_dp_sfcs(const HSystemPlan& hp) {
    const auto& h = m_plan.proto.h_system(hp.source);
    if (!h.has_program()) return;
    const auto& pr = h.program();
    for (int k = 0; k < pr.dpsyc_fr_size(); ++k)
      error_at(m_hlocate(hp.source, {{"program"}, {"dpsyc_fr", k}}),
               "h_system \"" + hp.name + "\": the program calls SFC 11 DPSYC_FR; an H CPU does not support it, "
               "in Solo and in Redundant mode (no SYNC/FREEZE of DP slave groups) (S7-400H manual 001 L14091-14096, "
               "L13668-13672; 000 L4112, L4262, D4)");
    for (int k = 0; k < pr.d_act_dp_size(); ++k)
      error_at(m_hlocate(hp.source, {{"program"}, {"d_act_dp", k}}),
               "h_system \"" + hp.name + "\": the program calls SFC 12 D_ACT_DP; an H CPU does not support it "
               "(DP slaves cannot be deactivated and activated) (S7-400H manual 001 L14098-14103, D4)");
  }

  /// C4: the addresses as devices::HIoMap assigns them (h_io_map.hpp): the driven systems in
  /// order, their slaves by PROFIBUS address (a switched station once, line A's slave first),
  /// the modules in slot order; then the expansion racks' modules.
  void check_process_image(const HSystemPlan& hp, const HProcessImageSize& pi) {
    std::size_t in = 0, out = 0;
    auto check = [&](std::size_t len, std::size_t& at, std::size_t size, const char* image,
                     const std::string& who, std::pair<int, int> where) {
      if (len > 0 && at < size && at + len > size)
        error_at(where, "h_system \"" + hp.name + "\": " + who + " (" + image + " octets " + std::to_string(at) +
                            ".." + std::to_string(at + len - 1) + ") straddles the end of the " + image +
                            " process image at " + std::to_string(size) +
                            " octets: a module lies wholly inside or wholly outside it (S7-400H manual 001 "
                            "§9.2.3 L8067-8072, C4)");
      at += len;
    };
    for (int s : hp.runtime->systems) {
      const RedundancyPlan& rs = m_plan.redundant_systems[static_cast<std::size_t>(s)];
      std::map<std::uint8_t, const DpSlavePlan*> by_address;
      for (int side = 1; side >= 0; --side)  // line A's slave wins an address both lines have
        for (const DpSlavePlan* sl : slaves_of(rs, side)) by_address[sl->address] = sl;
      for (auto [a, sl] : by_address)
        for (std::size_t m = 0; m < sl->config.modules.size(); ++m) {
          const auto t = module_totals(*sl, m);
          const std::string who = slave_name(*sl) + " module \"" + module_name(*sl, m) + "\"";
          check(t.inputs, in, pi.inputs, "input", who, module_at(*sl, m));
          check(t.outputs, out, pi.outputs, "output", who, module_at(*sl, m));
        }
    }
    const auto& h = m_plan.proto.h_system(hp.source);
    for (const auto& rack : hp.runtime->racks) {
      int x = 0;
      while (x < h.expansion_rack_size() && h.expansion_rack(x).number() != static_cast<std::uint32_t>(rack.number)) ++x;
      for (std::size_t m = 0; m < rack.modules.size(); ++m) {
        const auto where = m_hlocate(hp.source, {{"expansion_rack", x}, {"module", static_cast<int>(m)}});
        const std::string who = "expansion rack " + std::to_string(rack.number) + " module \"" + rack.modules[m].name + "\"";
        check(rack.modules[m].in_len, in, pi.inputs, "input", who, where);
        check(rack.modules[m].out_len, out, pi.outputs, "output", who, where);
      }
    }
  }

  // ---- per redundant system: D4 (second master, baud), D5 (slaves per interface and their
  // data), C1 (consistency) ----
  void check_system(int s, const HSystemPlan& hp) {
    const RedundancyPlan& rs = m_plan.redundant_systems[static_cast<std::size_t>(s)];
    const std::string sys = "redundant_master_system \"" + rs.name + "\" of h_system \"" + hp.name + "\"";
    const HCpuLimits& lim = has_cpu(hp) ? h_cpu_limits(cpu(hp).cpu_type())
                                        : h_cpu_limits(scenario::HCpuPair::CPU_417_4H);
    for (int side = 0; side < 2; ++side) {
      const int line = rs.line[side];
      if (line < 0) continue;
      const std::string& lname = m_plan.lines[static_cast<std::size_t>(line)].name;
      // D4: a second master on the line.
      for (std::size_t k = 0; k < m_plan.dp_masters.size(); ++k)
        if (m_plan.dp_masters[k].line == line && static_cast<int>(k) != rs.master[side])
          error_at(m_locate("dp_master", m_plan.dp_masters[k].source, "line", -1),
                   "dp_master " + std::to_string(m_plan.dp_masters[k].params.address) + " on line \"" + lname +
                       "\": a second DP master on a line of " + sys + kMultiMaster);
      for (int k = 0; k < m_plan.proto.master_size(); ++k)
        if (m_plan.proto.master(k).line() == lname)
          error_at(m_locate("master", k, "line", -1),
                   "master on line \"" + lname + "\": a second master on a line of " + sys + kMultiMaster);
      // D4: equidistance (docs/dp-equidistance.md).
      if (rs.master[side] >= 0) {
        const DpMasterPlan& own = m_plan.dp_masters[static_cast<std::size_t>(rs.master[side])];
        if (!m_plan.proto.dp_master(own.source).equidistant_cycle().empty())
          error_at(m_locate("dp_master", own.source, "equidistant_cycle", -1),
                   "dp_master " + std::to_string(own.params.address) + " on line \"" + lname +
                       "\": equidistant_cycle on a DP master of " + sys +
                       ": an H-system has no equidistance of DP slaves (S7-400H manual 001 "
                       "L14085-14089, L13663-13666, D4)");
      }
      // D5: the baud rate.
      if (m_plan.lines[static_cast<std::size_t>(line)].baud == bus::Baud::k31_25) {
        const auto& pl = m_plan.proto.line(line_source(lname));
        error_at(m_locate("line", line_source(lname), pl.has_bit_rate() ? "bit_rate" : "baud", -1),
                 "line \"" + lname + "\" of " + sys +
                     ": 31.25 kbit/s is PROFIBUS PA's rate; an H-system's DP master runs 9.6 kbit/s to "
                     "12 Mbit/s (S7-400H manual 000 L2030-2046, D5)");
      }
      // D5: slaves per interface; per slave and slot; C1.
      const MasterPlace p = place(rs, side);
      const std::size_t max = p.interface == Place::X1_MPI_DP ? lim.mpi_dp_slaves
                              : p.interface == Place::CP_443_5_EXT ? kCp443_5Slaves
                                                                    : lim.dp_slaves;
      auto slaves = slaves_of(rs, side);
      if (slaves.size() > max) {  // reported at the first slave over the limit by address
        std::stable_sort(slaves.begin(), slaves.end(),
                         [](const DpSlavePlan* x, const DpSlavePlan* y) { return x->address < y->address; });
        const DpSlavePlan& over = *slaves[max];
        error_at(m_locate(over.repeated, over.source, "address", -1),
                 slave_name(over) + " on line \"" + lname + "\": " + std::to_string(slaves.size()) +
                     " slaves on the DP master at " + p.str() + " of " + sys + "; " +
                     (p.interface == Place::CP_443_5_EXT ? std::string("a CP 443-5 Extended")
                                                         : std::string(lim.name) + "'s " + interface_name(p.interface)) +
                     " serves at most " + std::to_string(max) + " (" +
                     (p.interface == Place::CP_443_5_EXT ? std::string("S7-400H manual 000 L1724") : std::string(lim.slaves_source)) +
                     ", D5)");
      }
      for (const DpSlavePlan* sl : slaves)
        if (sl->switched < 0 || side == 0) check_slave_data(*sl, sys);
    }
  }

  static constexpr const char* kMultiMaster =
      ": an H-system's DP master system runs no multi-master operation in Redundant mode "
      "(S7-400H manual 001 L14070-14074, L13653-13655, D4)";

  int line_source(const std::string& name) const {
    for (int k = 0; k < m_plan.proto.line_size(); ++k)
      if (m_plan.proto.line(k).name() == name) return k;
    return 0;
  }

  /// D5 per slave (244 + 244 octets, 128 per slot) and C1 (consistent modules).
  void check_slave_data(const DpSlavePlan& sl, const std::string& sys) {
    for (auto [n, what] : {std::pair{sl.inputs, "inputs"}, std::pair{sl.outputs, "outputs"}})
      if (n > dp::kMaxIoLen)
        error_at(m_locate(sl.repeated, sl.source, "modules", -1),
                 slave_name(sl) + " of " + sys + ": " + std::to_string(n) + " octets of " + what +
                     "; a slave of an H-system's DP master has at most 244 (S7-400H manual 001 L12006-12010, D5)");
    for (std::size_t m = 0; m < sl.config.modules.size(); ++m) {
      std::vector<dp::CfgIdentifier> ids;
      if (dp::parse_cfg(sl.config.modules[m].cfg, ids, false) != dp::CfgError::None) continue;
      std::size_t len[2] = {0, 0}, consistent[2] = {0, 0};
      bool special = false;
      for (const auto& id : ids) {
        special |= id.special;
        const dp::CfgIo* io[2] = {&id.input, &id.output};
        for (int d = 0; d < 2; ++d) {
          len[d] += io[d]->bytes();
          if (io[d]->consistent) consistent[d] += io[d]->bytes();
        }
      }
      const std::string who = slave_name(sl) + " module \"" + module_name(sl, m) + "\" of " + sys;
      for (int d = 0; d < 2; ++d) {
        const char* what = d == 0 ? "input" : "output";
        if (len[d] > kMaxSlotOctets) {
          error_at(module_at(sl, m), who + ": " + std::to_string(len[d]) + " " + what +
                                         " octets in one slot; an H-system's DP master takes at most 128 per slot "
                                         "(S7-400H manual 001 L12006-12010, D5)");
          continue;
        }
        const std::size_t cmax = special ? kMaxConsistentSkf : kMaxConsistentAkf;
        if (consistent[d] > cmax)
          error_at(module_at(sl, m),
                   who + ": " + std::to_string(consistent[d]) + " " + what + " octets consistent over the whole length; " +
                       (special ? "with the special identifier format (SKF) at most 128"
                                : "with the general identifier format (AKF) at most 32") +
                       " (S7-400H manual 001 §4.10.4 L3387-3405, C1)");
      }
    }
  }

  /// The slaves of the master on `side` of `rs` (one-sided and switched interfaces), in file order.
  std::vector<const DpSlavePlan*> slaves_of(const RedundancyPlan& rs, int side) const {
    std::vector<const DpSlavePlan*> out;
    if (rs.master[side] < 0) return out;
    const DpMasterPlan& mp = m_plan.dp_masters[static_cast<std::size_t>(rs.master[side])];
    for (const auto& sl : m_plan.dp_slaves)
      if (sl.line == rs.line[side] && sl.master == mp.params.address) out.push_back(&sl);
    return out;
  }

  static dp::CfgTotals module_totals(const DpSlavePlan& sl, std::size_t m) {
    std::vector<dp::CfgIdentifier> ids;
    if (dp::parse_cfg(sl.config.modules[m].cfg, ids, false) != dp::CfgError::None) return {};
    return dp::cfg_totals(ids);
  }
  static std::string slave_name(const DpSlavePlan& sl) {
    return std::string(sl.switched >= 0 ? "switched_station " : "dp_slave ") + std::to_string(sl.address);
  }
  static std::string module_name(const DpSlavePlan& sl, std::size_t m) {
    return m < sl.module_names.size() ? sl.module_names[m] : sl.config.modules[m].name;
  }
  std::pair<int, int> module_at(const DpSlavePlan& sl, std::size_t m) const {
    // An IM 157 link's modules are its lower stations (docs/dp-link.md): `source` indexes its
    // y_link / dp_pa_link entry, which has no module list.
    if (sl.switched >= 0 && m_plan.switched[static_cast<std::size_t>(sl.switched)].link >= 0)
      return m_locate(sl.repeated, sl.source, "address", -1);
    const auto& names = sl.switched >= 0 ? m_plan.proto.switched_station(sl.source).modules()
                                         : m_plan.proto.dp_slave(sl.source).modules();
    if (static_cast<int>(m) < names.size()) return m_locate(sl.repeated, sl.source, "modules", static_cast<int>(m));
    return m_locate(sl.repeated, sl.source, "gsd", -1);
  }

  // ---- S10: placement ----
  MasterPlace place(const RedundancyPlan& rs, int side) const {
    const auto& r = m_plan.proto.redundant_master_system(rs.source);
    const Place& p = side == 0 ? r.place_a() : r.place_b();
    MasterPlace out;
    out.rack = p.has_rack() ? p.rack() : static_cast<unsigned>(side);
    out.interface = p.interface();
    if (p.has_slot())
      out.slot = p.slot();
    else if (out.interface != Place::CP_443_5_EXT)
      out.slot = kDefaultHCpuSlot;
    return out;
  }

  void check_places(const HSystemPlan& hp) {
    const auto& h = m_plan.proto.h_system(hp.source);
    std::set<int> seen;
    std::map<std::tuple<unsigned, int, unsigned>, std::string> used;  // (rack, interface, slot) -> system
    std::size_t cps[2] = {0, 0};
    for (std::size_t k = 0; k < hp.dp_systems.size(); ++k) {
      const int s = hp.dp_systems[k].system;
      if (s < 0 || !seen.insert(s).second) continue;
      const RedundancyPlan& rs = m_plan.redundant_systems[static_cast<std::size_t>(s)];
      const auto& r = m_plan.proto.redundant_master_system(rs.source);
      const std::string sys = "redundant_master_system \"" + rs.name + "\" of h_system \"" + hp.name + "\"";
      const MasterPlace p[2] = {place(rs, 0), place(rs, 1)};
      const char* field[2] = {"place_a", "place_b"};
      auto at = [&](int side) {
        const bool given = side == 0 ? r.has_place_a() : r.has_place_b();
        return m_locate("redundant_master_system", rs.source, given ? field[side] : "name", -1);
      };
      // The pair's error goes to place_b, or to place_a when only that one is given.
      auto pair_at = [&] { return at(r.has_place_b() || !r.has_place_a() ? 1 : 0); };
      bool ok = true;
      for (int side = 0; side < 2; ++side) {
        if (p[side].rack > 1) {
          error_at(at(side), sys + ": " + field[side] + " rack " + std::to_string(p[side].rack) +
                                 " is not a central rack (0 or 1): the DP masters of a redundant DP master "
                                 "system sit in the central racks (S7-400H manual 000 L2364, S10)");
          ok = false;
        }
        if (p[side].interface == Place::CP_443_5_EXT && (!p[side].slot || *p[side].slot < 1 || *p[side].slot > 18)) {
          error_at(at(side), sys + ": " + field[side] + ": a CP 443-5 Extended needs its slot: 1..18");
          ok = false;
        }
      }
      if (!ok) continue;
      if (p[0].rack == p[1].rack) {
        error_at(pair_at(), sys + ": both DP masters in rack " + std::to_string(p[0].rack) +
                            ": a redundant DP master system has one master in each central rack (S7-400H manual "
                            "000 L2362-2364, S10)");
        continue;
      }
      if (p[0].interface != p[1].interface || p[0].slot != p[1].slot) {
        error_at(pair_at(), sys + ": asymmetric placement: line A's master at " + p[0].str() + ", line B's at " +
                            p[1].str() + "; both masters sit at the same interface in the same slot (S7-400H "
                            "manual 000 L1782-1785, L2362-2364; 001 L5580-5587, S10)");
        continue;
      }
      for (int side = 0; side < 2; ++side) {
        const auto key = std::tuple{p[side].rack, static_cast<int>(p[side].interface),
                                    p[side].interface == Place::CP_443_5_EXT ? *p[side].slot : 0u};
        auto [it, fresh] = used.emplace(key, rs.name);
        if (!fresh) {
          error_at(at(side), sys + ": " + p[side].str() + " is already the DP master of redundant_master_system \"" +
                                 it->second + "\": one interface, one DP master system (S7-400H manual 000 L1722, S10)");
          break;
        }
        if (p[side].interface == Place::CP_443_5_EXT && ++cps[p[side].rack] == kMaxHCpMasters + 1)
          error_at(at(side), sys + ": more than 10 CP 443-5 Extended DP masters in rack " +
                                 std::to_string(p[side].rack) + " (S7-400H manual 000 L1722, D5)");
      }
      if (p[0].interface == Place::X1_MPI_DP && h.has_cpu() && h.cpu().has_mpi())
        error_at(at(0), sys + ": X1 is the CPUs' MPI interface (cpu.mpi), so it cannot also be a DP master: "
                              "the MPI/DP interface runs as MPI or as DP (S7-400H manual 001 L11943, L11963, S10)");
    }
  }

  const ScenarioPlan& m_plan;
  const DpLocator& m_locate;
  const HLocator& m_hlocate;
  std::vector<Diagnostic>& m_errors;
};

}  // namespace

void check_h_config_rules(const ScenarioPlan& plan, const DpLocator& locate, const HLocator& hlocate,
                          std::vector<Diagnostic>& errors) {
  RuleChecker(plan, locate, hlocate, errors).run();
}

}  // namespace pbvbus::tools
