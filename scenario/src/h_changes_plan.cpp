// The scenario fields of docs/h-scenario-changes.md (h_plan.hpp plan_h_changes,
// plan_switch_to_cpu): battery and RAM test, T8's link-up time, the DBs' 5.2.3 attributes,
// watchdog OBs, OB 72's SFC 27 and the racks' partitions, and the fault switch_to_cpu.
#include <algorithm>
#include <string>

#include "pbvbus/s7h/h_update_timing.hpp"
#include "pbvbus/scenario/h_plan.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

std::vector<HPathStep> with(std::vector<HPathStep> p, HPathStep s) {
  p.push_back(s);
  return p;
}

std::optional<bus::Ticks> duration(const std::string& text, const std::vector<HPathStep>& at,
                                   const ProgramError& error) {
  const auto t = bus::parse_duration(text);
  if (!t) error(at, "bad duration \"" + text + "\" for " + at.back().field + " (e.g. \"100ms\")");
  return t;
}

/// HCpu.battery / ram_mb (000 L640, L786; 001 L1149-1153).
void plan_rack_power(const scenario::HCpuPair& c, HChangesPlan& out, const ProgramError& error) {
  const scenario::HCpu* cpu[2] = {&c.cpu0(), &c.cpu1()};
  const char* name[2] = {"cpu0", "cpu1"};
  devices::HRackPowerParams p;
  bool any = false;
  std::optional<std::uint32_t> ram;
  for (int r = 0; r < 2; ++r) {
    if (cpu[r]->has_battery()) {
      p.battery[static_cast<std::size_t>(r)] = cpu[r]->battery();
      any |= !cpu[r]->battery();
    }
    if (!cpu[r]->has_ram_mb()) continue;
    if (cpu[r]->ram_mb() > 64 * 1024) {
      error({{"cpu"}, {name[r]}, {"ram_mb"}}, "ram_mb " + std::to_string(cpu[r]->ram_mb()) + " is above 65536");
      continue;
    }
    // Decision: the two CPUs of a pair have the same memory (000 L1112: only the switch to CPU
    // with modified configuration runs CPUs with different memories, and that is not power-on).
    if (ram && *ram != cpu[r]->ram_mb()) {
      error({{"cpu"}, {name[r]}, {"ram_mb"}},
            "ram_mb " + std::to_string(cpu[r]->ram_mb()) + " differs from cpu0's " + std::to_string(*ram) +
                " (both CPUs of a pair have the same RAM)");
      continue;
    }
    ram = cpu[r]->ram_mb();
  }
  if (ram) p.ram_kb = *ram * 1024;
  if (any || p.ram_kb > 0) out.rack_power = p;
}

/// T8: LINK-UP = (load + work memory) MB x 1 s + base (000 §5.3.1 L1364-1374).
void plan_t8(const scenario::HCpuPair& c, devices::HCpuPairParams& pair, const ProgramError& error) {
  // Decision: the base ("a few seconds", L1374) defaults to 1 s, so that 1 MB gives the pair's
  // default link-up of 2 s (h_cpu_pair.hpp: "1 MB x 1 s of copy + 1 s base").
  bus::Ticks base = bus::kTicksPerSecond;
  if (!c.link_up_base_time().empty()) {
    const auto t = duration(c.link_up_base_time(), {{"cpu"}, {"link_up_base_time"}}, error);
    if (t && *t < 0) error({{"cpu"}, {"link_up_base_time"}}, "link_up_base_time must not be negative");
    if (!t || *t < 0) return;
    base = *t;
  }
  if (!c.has_load_memory_mb()) {
    if (c.has_work_memory_mb() || !c.link_up_base_time().empty())
      error({{"cpu"}, {c.has_work_memory_mb() ? "work_memory_mb" : "link_up_base_time"}},
            "work_memory_mb and link_up_base_time need load_memory_mb (T8: the link-up from the memory size)");
    return;
  }
  if (!c.link_up_time().empty()) {
    error({{"cpu"}, {"load_memory_mb"}},
          "load_memory_mb derives the link-up time (T8): remove link_up_time or load_memory_mb");
    return;
  }
  const std::uint64_t mb = std::uint64_t{c.load_memory_mb()} + c.work_memory_mb();
  if (mb > 64 * 1024) {
    error({{"cpu"}, {"load_memory_mb"}}, "load_memory_mb + work_memory_mb is above 65536 MB");
    return;
  }
  const devices::Us b = base / bus::kTicksPerUs;
  pair.link_up_time = devices::to_ticks(devices::link_up_time(static_cast<std::int64_t>(mb) * 1024, b));
}

void plan_db_blocks(const scenario::HCpuPair& c, HChangesPlan& out) {
  for (const auto& d : c.s7_memory().db()) {
    devices::HDbBlock b;
    b.number = static_cast<int>(d.number());
    b.interface_stamp = 1;
    b.read_only = d.read_only();
    b.unlinked = d.unlinked();
    b.comm_sfb_instances = d.sfb_instances();
    b.kb = (d.size() + 1023) / 1024;
    out.db_blocks.push_back(b);
  }
}

const scenario::S7DataBlock* find_db(const scenario::HCpuPair& c, std::uint32_t number) {
  for (const auto& d : c.s7_memory().db())
    if (d.number() == number) return &d;
  return nullptr;
}

void plan_watchdogs(const scenario::HSystem& h, HChangesPlan& out, const ProgramError& error) {
  const auto& prog = h.program();
  for (int k = 0; k < prog.watchdog_ob_size(); ++k) {
    const auto& w = prog.watchdog_ob(k);
    const std::vector<HPathStep> at{{"program"}, {"watchdog_ob", k}};
    HWatchdogPlan p;
    if (w.ob() < 30 || w.ob() > 38) {
      error(with(at, {"ob"}), "watchdog_ob: OB " + std::to_string(w.ob()) + " is not a watchdog OB 30..38");
      continue;
    }
    p.ob = static_cast<int>(w.ob());
    if (std::any_of(out.watchdogs.begin(), out.watchdogs.end(), [&](const HWatchdogPlan& o) { return o.ob == p.ob; })) {
      error(with(at, {"ob"}), "watchdog_ob: OB " + std::to_string(p.ob) + " is given twice");
      continue;
    }
    if (w.cycle().empty()) {
      error(at, "watchdog_ob needs a cycle, e.g. cycle: \"100ms\"");
      continue;
    }
    const auto cycle = duration(w.cycle(), with(at, {"cycle"}), error);
    if (!cycle) continue;
    if (*cycle <= 0) {
      error(with(at, {"cycle"}), "watchdog_ob: cycle must be longer than 0");
      continue;
    }
    p.cycle = *cycle;
    if (!w.phase().empty()) {
      const auto phase = duration(w.phase(), with(at, {"phase"}), error);
      if (!phase) continue;
      if (*phase < 0 || *phase >= p.cycle) {
        error(with(at, {"phase"}), "watchdog_ob: phase " + w.phase() + " is not below the cycle " + w.cycle());
        continue;
      }
      p.phase = *phase;
    }
    p.width = w.has_width() ? w.width() : 2;
    if (p.width != 1 && p.width != 2 && p.width != 4) {
      error(with(at, {"width"}), "watchdog_ob: width " + std::to_string(p.width) + " is not 1, 2 or 4");
      continue;
    }
    if (w.has_db()) {
      const scenario::S7DataBlock* d = find_db(h.cpu(), w.db());
      if (d == nullptr) {
        error(with(at, {"db"}), "watchdog_ob: DB " + std::to_string(w.db()) + " is not in cpu.s7_memory");
        continue;
      }
      if (std::uint64_t{w.offset()} + p.width > d->size()) {
        error(with(at, {"offset"}), "watchdog_ob: DBB " + std::to_string(w.offset()) + " + " +
                                        std::to_string(p.width) + " is beyond DB " + std::to_string(w.db()) +
                                        "'s " + std::to_string(d->size()) + " octets");
        continue;
      }
      p.db = static_cast<std::uint16_t>(w.db());
      p.offset = w.offset();
    }
    out.watchdogs.push_back(p);
  }
}

/// HRackModule.partition and HProgram.ob72_updat_po (000 L1752; SFC 27 PART 1..15).
void plan_partitions(const scenario::HSystem& h, HRuntimePlan& rt, const ProgramError& error) {
  std::vector<int> used;
  for (int k = 0; k < h.expansion_rack_size(); ++k) {
    const auto& x = h.expansion_rack(k);
    for (int m = 0; m < x.module_size(); ++m) {
      const std::uint32_t part = x.module(m).partition();
      if (part == 0) continue;
      if (part > 15) {
        error({{"expansion_rack", k}, {"module", m}, {"partition"}},
              "partition " + std::to_string(part) + " is not 1..15 (0: the OB 1 image)");
        continue;
      }
      for (auto& r : rt.racks)
        if (r.number == static_cast<int>(x.number()) && static_cast<std::size_t>(m) < r.modules.size())
          r.modules[static_cast<std::size_t>(m)].partition = static_cast<int>(part);
      used.push_back(static_cast<int>(part));
    }
  }
  const auto& prog = h.program();
  for (int k = 0; k < prog.ob72_updat_po_size(); ++k) {
    const std::uint32_t part = prog.ob72_updat_po(k);
    if (part < 1 || part > 15) {
      error({{"program"}, {"ob72_updat_po", k}}, "ob72_updat_po: partition " + std::to_string(part) +
                                                   " is not 1..15 (SFC 27 refuses it with W#16#8090)");
      continue;
    }
    rt.changes.ob72_updat_po.push_back(static_cast<int>(part));
  }
}

}  // namespace

void plan_h_changes(const ScenarioPlan& plan, int i, HRuntimePlan& rt, const ProgramError& error) {
  const scenario::HSystem& h = plan.proto.h_system(i);
  plan_rack_power(h.cpu(), rt.changes, error);
  plan_t8(h.cpu(), rt.pair, error);
  plan_db_blocks(h.cpu(), rt.changes);
  plan_watchdogs(h, rt.changes, error);
  plan_partitions(h, rt, error);
}

bool plan_switch_to_cpu(const ScenarioPlan& plan, int hi, const scenario::HSwitchToCpu& s,
                        HSwitchPlan& out, const ProgramError& error) {
  const HSystemPlan& hp = plan.h_systems.at(static_cast<std::size_t>(hi));
  const HRuntimePlan& rt = *hp.runtime;
  const scenario::HCpuPair& cpu = plan.proto.h_system(hp.source).cpu();
  using V = scenario::HSwitchToCpu;
  out.variant = s.variant() == V::EXPANDED_MEMORY ? devices::HSwitchVariant::ExpandedMemory
                : s.variant() == V::MODIFIED_OS   ? devices::HSwitchVariant::ModifiedOs
                                                  : devices::HSwitchVariant::ModifiedConfiguration;
  const auto config = [](const scenario::HCpuMemory& m) {
    devices::HCpuConfig c;
    c.work_memory_kb = m.work_memory_kb();
    c.load_memory_kb = m.load_memory_kb();
    c.load_memory = m.flash() ? devices::LoadMemoryType::Flash : devices::LoadMemoryType::Ram;
    c.os_version = m.os_version();
    return c;
  };
  out.master = config(s.master());
  out.standby = config(s.standby());
  bool good = true;
  for (int k = 0; k < s.added_module_size(); ++k) {
    const auto& a = s.added_module(k);
    const std::vector<HPathStep> at{{"added_module", k}};
    int sys = -1;
    for (std::size_t x = 0; x < rt.systems.size(); ++x)
      if (plan.redundant_systems[static_cast<std::size_t>(rt.systems[x])].name == a.system())
        sys = static_cast<int>(x);
    if (sys < 0) {
      error(with(at, {"system"}), "switch_to_cpu: \"" + a.system() +
                                      "\" is not a redundant_master_system this h_system drives");
      good = false;
      continue;
    }
    if (!a.has_address()) {
      error(at, "switch_to_cpu: an added module needs the address of its switched_station");
      good = false;
      continue;
    }
    const DpSlavePlan* station = nullptr;
    for (const SwitchedPlan& x : plan.switched)
      if (x.system == rt.systems[static_cast<std::size_t>(sys)] && x.address == a.address() && x.slave[0] >= 0)
        station = &plan.dp_slaves[static_cast<std::size_t>(x.slave[0])];
    if (station == nullptr) {
      error(with(at, {"address"}), "switch_to_cpu: redundant_master_system \"" + a.system() +
                                       "\" has no switched_station " + std::to_string(a.address()));
      good = false;
      continue;
    }
    if (a.module_index() >= station->module_names.size()) {
      error(with(at, {"module_index"}), "switch_to_cpu: module_index " + std::to_string(a.module_index()) +
                                            " is not below the " + std::to_string(station->module_names.size()) +
                                            " modules of station " + std::to_string(a.address()));
      good = false;
      continue;
    }
    out.added.push_back({sys, static_cast<std::uint8_t>(a.address()), a.module_index()});
  }
  for (int k = 0; k < s.changed_db_size(); ++k) {
    if (find_db(cpu, s.changed_db(k)) == nullptr) {
      error({{"changed_db", k}}, "switch_to_cpu: DB " + std::to_string(s.changed_db(k)) +
                                     " is not in the h_system's cpu.s7_memory");
      good = false;
      continue;
    }
    out.changed_db.push_back(static_cast<int>(s.changed_db(k)));
  }
  return good;
}

}  // namespace pbvbus::tools
