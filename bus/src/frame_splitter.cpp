#include "pbvbus/bus/frame_splitter.hpp"

namespace pbvbus::bus {

int telegram_length(std::span<const std::uint8_t> head) {
  if (head.empty()) return 0;
  switch (head[0]) {
    case 0xE5: return 1;   // SC
    case 0xDC: return 3;   // SD4 token: DC DA SA
    case 0x10: return 6;   // SD1: 10 DA SA FC FCS ED
    case 0xA2: return 14;  // SD3: A2 DA SA FC 8 octets FCS ED
    case 0x68: {           // SD2: 68 LE LEr 68 DA SA FC ... FCS ED
      if (head.size() < 2) return 0;
      const int le = head[1];
      if (le < 4 || le > 249) return -1;
      if (head.size() < 3) return 0;
      if (head[2] != le) return -1;
      if (head.size() < 4) return 0;
      if (head[3] != 0x68) return -1;
      return le + 6;
    }
    default: return -1;
  }
}

}  // namespace pbvbus::bus
