// Set_Prm layout (protocol-facts.md §D.2).
#include "pbvbus/dp/prm.hpp"

#include <algorithm>

namespace pbvbus::dp {

bool parse_prm(std::span<const std::uint8_t> du, PrmView& out) {
  if (du.size() < kPrmLenNorm) return false;
  out.header.station_status = du[0];
  out.header.wd_fact_1 = du[1];
  out.header.wd_fact_2 = du[2];
  out.header.min_tsdr = du[3];
  out.header.ident = static_cast<std::uint16_t>((du[4] << 8) | du[5]);
  out.header.group_ident = du[6];
  out.user_prm = du.subspan(kPrmLenNorm);
  return true;
}

std::vector<std::uint8_t> encode_prm(const PrmHeader& h, std::span<const std::uint8_t> user_prm) {
  // Sized once and filled in place (GCC 12 warns spuriously about insert() after a braced init).
  std::vector<std::uint8_t> du(kPrmLenNorm + user_prm.size());
  du[0] = h.station_status;
  du[1] = h.wd_fact_1;
  du[2] = h.wd_fact_2;
  du[3] = h.min_tsdr;
  du[4] = static_cast<std::uint8_t>(h.ident >> 8);
  du[5] = static_cast<std::uint8_t>(h.ident & 0xFF);
  du[6] = h.group_ident;
  std::copy(user_prm.begin(), user_prm.end(), du.begin() + kPrmLenNorm);
  return du;
}

bool split_prm_blocks(std::span<const std::uint8_t> octets, std::vector<PrmBlock>& out) {
  out.clear();
  std::size_t i = 0;
  while (i < octets.size()) {
    const std::size_t len = octets[i];
    if (len < 4 || octets.size() - i < len) return false;
    PrmBlock b;
    b.type = octets[i + 1];
    b.slot = octets[i + 2];
    b.specifier = octets[i + 3];
    b.bytes = octets.subspan(i, len);
    out.push_back(b);
    i += len;
  }
  return true;
}

}  // namespace pbvbus::dp
