// SFC 14 DPRD_DAT, SFC 15 DPWR_DAT and SFC 11's parameter check (h_dp_sfc.hpp; docs/h-dp-sfc.md).
#include "pbvbus/s7h/h_dp_sfc.hpp"

#include <algorithm>

namespace pbvbus::devices {

namespace {
bool inside(std::size_t at, std::size_t len, std::size_t size) { return at <= size && len <= size - at; }
}  // namespace

bool store_ret_val(std::span<std::uint8_t> mem, std::uint32_t at, std::uint16_t ret_val) {
  if (!inside(at, 2, mem.size())) return false;
  mem[at] = static_cast<std::uint8_t>(ret_val >> 8);
  mem[at + 1] = static_cast<std::uint8_t>(ret_val & 0xFF);
  return true;
}

std::uint16_t dprd_dat(const DpReadCall& c, std::span<const IoModuleExtent> modules,
                       std::span<const std::uint8_t> pii, std::span<std::uint8_t> mem) {
  std::uint16_t rv = kSfcNoModule;
  const auto m = std::find_if(modules.begin(), modules.end(), [&](const IoModuleExtent& e) {
    return e.in_len > 0 && e.in_addr == c.laddr;
  });
  if (m != modules.end()) {
    if (!m->dp)
      rv = kSfcNotDp;
    else if (c.length != m->in_len)
      rv = kSfcWrongLength;  // 001 L3352-3354: the configured length
    else if (!inside(c.record, c.length, mem.size()))
      rv = area_write_error(3);  // RECORD is parameter 3
    else if (!inside(m->in_addr, m->in_len, pii.size()))
      rv = kSfcNoModule;  // beyond the image: not exchanged
    else {
      std::copy_n(pii.begin() + m->in_addr, m->in_len, mem.begin() + c.record);
      rv = kSfcOk;
    }
  }
  if (c.ret_val) store_ret_val(mem, *c.ret_val, rv);
  return rv;
}

std::uint16_t dpwr_dat(const DpWriteCall& c, std::span<const IoModuleExtent> modules,
                       std::span<std::uint8_t> piq, std::span<std::uint8_t> mem) {
  std::uint16_t rv = kSfcNoModule;
  const auto m = std::find_if(modules.begin(), modules.end(), [&](const IoModuleExtent& e) {
    return e.out_len > 0 && e.out_addr == c.laddr;
  });
  if (m != modules.end()) {
    if (!m->dp)
      rv = kSfcNotDp;
    else if (c.length != m->out_len)
      rv = kSfcWrongLength;  // 001 L3362-3365
    else if (!inside(c.record, c.length, mem.size()))
      rv = area_read_error(2);  // RECORD is parameter 2
    else if (!inside(m->out_addr, m->out_len, piq.size()))
      rv = kSfcNoModule;
    else {
      std::copy_n(mem.begin() + c.record, c.length, piq.begin() + m->out_addr);
      rv = kSfcOk;
    }
  }
  if (c.ret_val) store_ret_val(mem, *c.ret_val, rv);
  return rv;
}

void run_dp_sfcs(const ProgramSpec& spec, std::span<const std::uint8_t> pii,
                 std::span<std::uint8_t> piq, std::span<std::uint8_t> mem, bus::Ticks now) {
  for (const auto& c : spec.dprd_dat)
    if (c.at <= now) dprd_dat(c, spec.io_modules, pii, mem);
  for (const auto& c : spec.dpwr_dat)
    if (c.at <= now) dpwr_dat(c, spec.io_modules, piq, mem);
}

std::uint16_t check_dpsyc_fr(std::uint8_t group, std::uint8_t mode) {
  constexpr std::uint8_t kCommands = 0x3C;  // SYNC 0x20, UNSYNC 0x10, FREEZE 0x08, UNFREEZE 0x04
  if ((mode & kCommands) == 0 || (mode & ~kCommands) != 0) return kDpsycBadMode;
  if (group == 0) return kDpsycBadGroup;
  return 0;
}

}  // namespace pbvbus::devices
