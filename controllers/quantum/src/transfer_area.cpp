#include "pbvbus/quantum/transfer_area.hpp"

#include <algorithm>
#include <array>

#include "pbvbus/quantum/command_register.hpp"

namespace pbvbus::quantum {
namespace {

constexpr std::array<RefType, 4> kOrder = {RefType::Coil0x, RefType::Input1x, RefType::Register3x,
                                           RefType::Register4x};

const char* type_words(RefType t) {
  switch (t) {
    case RefType::Coil0x:
      return "coils (0x)";
    case RefType::Input1x:
      return "discrete inputs (1x)";
    case RefType::Register3x:
      return "input registers (3x)";
    case RefType::Register4x:
      return "holding registers (4x)";
  }
  return "";
}

std::uint32_t size_of(const StateRamSizes& s, RefType t) {
  switch (t) {
    case RefType::Coil0x:
      return s.coils;
    case RefType::Input1x:
      return s.inputs;
    case RefType::Register3x:
      return s.input_regs;
    case RefType::Register4x:
      return s.holding;
  }
  return 0;
}

std::array<std::uint32_t, 4> user_counts(const TransferConfig& c) {
  return {c.coils, c.inputs, c.input_regs, c.holding};
}
std::array<std::uint32_t, 4> additional_counts(const TransferConfig& c) {
  return {c.additional.coils, c.additional.inputs, c.additional.input_regs, c.additional.holding};
}

TransferPlanResult refuse(std::string why) {
  return {std::nullopt, std::move(why)};
}

void set_every_scan(TransferPlan& p, const std::array<std::uint32_t, 4>& counts) {
  for (std::size_t i = 0; i < kOrder.size(); ++i)
    if (counts[i] != 0) p.every_scan.push_back({kOrder[i], 0, counts[i]});
}

std::array<std::uint32_t, 4> whole_tables(const StateRamSizes& s) {
  return {s.coils, s.inputs, s.input_regs, s.holding};
}

}  // namespace

std::pair<std::uint32_t, std::uint32_t> allocate_12k_registers(std::uint32_t r3, std::uint32_t r4) {
  if (std::uint64_t{r3} + r4 <= kTwelveKRegisters) return {r3, r4};
  const std::uint32_t unused4 = r4 < kTwelveK4x ? kTwelveK4x - r4 : 0;
  const std::uint32_t t3 = std::min(r3, kTwelveK3x + unused4);
  std::uint32_t t4 = std::min(r4, kTwelveKRegisters - t3);
  if (t4 != r4) t4 = std::min(r4, (t4 + 15U) / 16U * 16U);
  return {t3, t4};
}

std::uint32_t per_scan_count(const TransferPlan& plan, RefType type) {
  for (const TransferRange& r : plan.every_scan)
    if (r.type == type) return r.first + r.count;
  return 0;
}

std::uint32_t state_ram_bytes(const StateRamSizes& s) {
  const std::uint64_t words = (std::uint64_t{s.coils} + 15) / 16 +
                              (std::uint64_t{s.inputs} + 15) / 16 + s.input_regs + s.holding;
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(words * 2, 0xFFFFFFFFU));
}

TransferPlanResult plan_transfer(const TransferConfig& cfg, const StateRamSizes& sizes) {
  using Mode = TransferConfig::Mode;
  TransferPlan plan;
  if (cfg.iec) {
    // IEC Hot Standby transfers the whole state RAM every scan (p. 51), with the IEC heap in
    // its transfer buffer; the CHS carries at most 128 KB (p. 48).
    if (cfg.mode == Mode::UserDefined || cfg.additional.enabled)
      return refuse(
          "IEC Hot Standby transfers all of state RAM; a user defined or additional transfer "
          "area is not allowed");
    const std::uint64_t ram = state_ram_bytes(sizes);
    const std::uint64_t total = ram + cfg.iec_heap_bytes;
    if (total > kIecTransferLimitBytes)
      return refuse("state RAM (" + std::to_string(ram) + " B) plus IEC heap (" +
                    std::to_string(cfg.iec_heap_bytes) + " B) is " + std::to_string(total) +
                    " B, more than the 131072 B (128 KB) an IEC Hot Standby transfer carries");
    set_every_scan(plan, whole_tables(sizes));
  } else if (cfg.mode == Mode::Default12K) {
    // User defined and additional entries are ignored with 12K (p. 98).
    const auto [t3, t4] = allocate_12k_registers(sizes.input_regs, sizes.holding);
    set_every_scan(
        plan, {std::min(sizes.coils, kTwelveKBits), std::min(sizes.inputs, kTwelveKBits), t3, t4});
  } else if (cfg.mode == Mode::TransferAll) {
    const auto u = user_counts(cfg);
    if (cfg.additional.enabled || std::any_of(u.begin(), u.end(), [](auto v) { return v != 0; }))
      return refuse(
          "\"Transfer All State RAM\" does not allow a user defined or additional state RAM "
          "range");
    set_every_scan(plan, whole_tables(sizes));
  } else {
    const auto u = user_counts(cfg);
    for (std::size_t i = 0; i < kOrder.size(); ++i) {
      if (u[i] % 16 != 0)
        return refuse("a user defined transfer of " + std::to_string(u[i]) + " " +
                      type_words(kOrder[i]) + " is not 0 or a multiple of 16");
      if (u[i] > size_of(sizes, kOrder[i]))
        return refuse("a user defined transfer of " + std::to_string(u[i]) + " " +
                      type_words(kOrder[i]) + " exceeds the " +
                      std::to_string(size_of(sizes, kOrder[i])) + " configured in state RAM");
    }
    if (cfg.holding < 16)
      return refuse("a user defined transfer needs at least 16 holding registers (4x), " +
                    std::to_string(cfg.holding) + " given");
    set_every_scan(plan, u);
    if (cfg.additional.enabled) {
      const auto a = additional_counts(cfg);
      const int scans = cfg.additional.scans;
      if (scans < 1 || scans > 255)
        return refuse("additional state RAM is spread over " + std::to_string(scans) +
                      " scans, the extra transfer time must be 1 to 255 scans");
      for (std::size_t i = 0; i < kOrder.size(); ++i) {
        if (a[i] % 16 != 0)
          return refuse("an additional transfer of " + std::to_string(a[i]) + " " +
                        type_words(kOrder[i]) + " is not 0 or a multiple of 16");
        if (std::uint64_t{u[i]} + a[i] > size_of(sizes, kOrder[i]))
          return refuse(std::string("the additional ") + type_words(kOrder[i]) + " after the " +
                        std::to_string(u[i]) + " sent every scan end at " +
                        std::to_string(u[i] + a[i]) + ", beyond the " +
                        std::to_string(size_of(sizes, kOrder[i])) + " configured in state RAM");
      }
      if (std::all_of(a.begin(), a.end(), [](auto v) { return v == 0; }))
        return refuse(
            "\"Transfer Additional State RAM\" is enabled with no additional references: the "
            "controller won't start (enter 16 or more of at least one type)");
      // Spread each type in groups of 16 over the scans, the first slices taking one group
      // more when they do not divide evenly; each slice's range follows the previous one.
      plan.additional_slices.assign(static_cast<std::size_t>(scans), {});
      for (std::size_t i = 0; i < kOrder.size(); ++i) {
        const std::uint32_t groups = a[i] / 16;
        const std::uint32_t base = groups / static_cast<std::uint32_t>(scans);
        const std::uint32_t extra = groups % static_cast<std::uint32_t>(scans);
        std::uint32_t next = u[i];
        for (std::uint32_t k = 0; k < static_cast<std::uint32_t>(scans); ++k) {
          const std::uint32_t n = (base + (k < extra ? 1 : 0)) * 16;
          if (n == 0) continue;
          plan.additional_slices[k].push_back({kOrder[i], next, n});
          next += n;
        }
      }
    }
  }

  const std::uint32_t per4x = per_scan_count(plan, RefType::Register4x);
  if (std::string e = check_non_transfer_area(cfg.non_transfer, per4x); !e.empty())
    return refuse(std::move(e));
  plan.non_transfer = cfg.non_transfer;
  const bool twelve_k = !cfg.iec && cfg.mode == Mode::Default12K;
  if (std::string e =
          check_command_register(cfg.command_register, per4x, twelve_k, cfg.non_transfer);
      !e.empty())
    return refuse(std::move(e));
  return {std::move(plan), {}};
}

}  // namespace pbvbus::quantum
