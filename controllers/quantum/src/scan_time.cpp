#include "pbvbus/quantum/scan_time.hpp"

namespace pbvbus::quantum {
namespace {

/// num / den rounded to the nearest integer, halves away from zero (den > 0).
std::int64_t round_div(std::int64_t num, std::int64_t den) {
  return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

}  // namespace

RefCounts baseline(CpuType cpu) {
  switch (cpu) {
    case CpuType::X13:
      return {1536, 512, 3000, 1872, 0};
    case CpuType::Cpu42402:
      return {1536, 512, 1212, 1872, 0};
    case CpuType::Cpu43412:
      return {1536, 512, 512, 1872, 700};
  }
  return {};
}

bus::Ticks hsby_cost(CpuType cpu) {
  return (cpu == CpuType::X13 ? 25 : 40) * bus::kTicksPerMs;
}

std::int64_t rate_us_per_1000_bytes(CpuType cpu) {
  switch (cpu) {
    case CpuType::X13:
      return 1600;
    case CpuType::Cpu42402:
      return 2000;
    case CpuType::Cpu43412:
      return 1900;
  }
  return 0;
}

ScanEstimate estimate_scan(CpuType cpu, const ScanInputs& in) {
  const RefCounts b = baseline(cpu);
  ScanEstimate e;
  e.deltas.coils = in.transferred.coils - b.coils;
  e.deltas.inputs = in.transferred.inputs - b.inputs;
  e.deltas.input_regs = in.transferred.input_regs - b.input_regs;
  e.deltas.holding = in.transferred.holding - b.holding;
  e.deltas.iec_regs = in.transferred.iec_regs;  // the seed's IEC example: all of them
  // Bits per reference: 0x and 1x 3, 3x 16, 4x 18 (2 B + 2 bits), IEC 3x 16.
  e.coil_bytes = round_div(e.deltas.coils * 3, 8);
  e.input_bytes = round_div(e.deltas.inputs * 3, 8);
  e.input_reg_bytes = e.deltas.input_regs * 2;
  e.holding_bytes = round_div(e.deltas.holding * 18, 8);
  e.iec_bytes = e.deltas.iec_regs * 2;
  e.bytes = e.coil_bytes + e.input_bytes + e.input_reg_bytes + e.holding_bytes + e.iec_bytes;

  const std::int64_t rate = in.rate_override.value_or(rate_us_per_1000_bytes(cpu));
  e.transfer = e.bytes * rate * bus::kTicksPerUs / 1000;
  e.transfer_ms = round_div(e.bytes * rate, 1'000'000);
  e.hsby = hsby_cost(cpu);
  e.standalone = in.standalone;
  const bus::Ticks hsby_part = e.hsby + e.transfer > 0 ? e.hsby + e.transfer : 0;
  e.total = e.standalone + hsby_part;
  const std::int64_t hsby_ms = e.hsby / bus::kTicksPerMs + e.transfer_ms;
  e.total_ms = round_div(e.standalone, bus::kTicksPerMs) + (hsby_ms > 0 ? hsby_ms : 0);
  return e;
}

}  // namespace pbvbus::quantum
