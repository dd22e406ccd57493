#include "pbvbus/bus/time.hpp"

#include <cstdio>

namespace pbvbus::bus {

__extension__ typedef __int128 Wide;

std::string_view baud_name(Baud b) {
  switch (b) {
    case Baud::k9_6: return "9.6k";
    case Baud::k19_2: return "19.2k";
    case Baud::k31_25: return "31.25k";
    case Baud::k45_45: return "45.45k";
    case Baud::k93_75: return "93.75k";
    case Baud::k187_5: return "187.5k";
    case Baud::k500: return "500k";
    case Baud::k1_5M: return "1.5M";
    case Baud::k3M: return "3M";
    case Baud::k6M: return "6M";
    case Baud::k12M: return "12M";
  }
  return "?";
}

std::optional<Baud> parse_baud(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  for (std::string_view suffix : {"bit/s", "bps", "baud", "Bd"}) {
    if (s.size() > suffix.size() && s.substr(s.size() - suffix.size()) == suffix) {
      s.remove_suffix(suffix.size());
      break;
    }
  }
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  // A decimal number of bit/s, kbit/s or Mbit/s, converted exactly: "1.5M", "1500k", "1500000",
  // "45.45k". Anything that is not exactly one of the PROFIBUS rates is rejected.
  std::uint64_t scale = 1;
  if (!s.empty() && (s.back() == 'k' || s.back() == 'K')) {
    scale = 1'000;
    s.remove_suffix(1);
  } else if (!s.empty() && s.back() == 'M') {
    scale = 1'000'000;
    s.remove_suffix(1);
  }
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);  // "19.2 kbit/s"
  std::uint64_t whole = 0, frac = 0, frac_div = 1;
  std::size_t i = 0;
  bool any = false;
  for (; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i, any = true) {
    if (whole > 100'000'000) return std::nullopt;
    whole = whole * 10 + static_cast<std::uint64_t>(s[i] - '0');
  }
  if (i < s.size() && s[i] == '.') {
    for (++i; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i, any = true) {
      if (frac_div >= 1'000'000) return std::nullopt;
      frac = frac * 10 + static_cast<std::uint64_t>(s[i] - '0');
      frac_div *= 10;
    }
  }
  if (!any || i != s.size()) return std::nullopt;
  if ((frac * scale) % frac_div != 0) return std::nullopt;
  const std::uint64_t v = whole * scale + frac * scale / frac_div;
  for (Baud b : kAllBauds)
    if (static_cast<std::uint64_t>(b) == v) return b;
  return std::nullopt;
}

std::optional<Ticks> parse_duration(std::string_view s) {
  // Integer part and optional fraction, parsed exactly as a decimal.
  std::size_t i = 0;
  std::int64_t whole = 0;
  std::int64_t frac = 0;
  std::int64_t frac_div = 1;
  bool any = false;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    if (whole > (INT64_MAX / 10) - 10) return std::nullopt;
    whole = whole * 10 + (s[i] - '0');
    ++i;
    any = true;
  }
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
      if (frac_div < 1'000'000'000'000LL) {
        frac = frac * 10 + (s[i] - '0');
        frac_div *= 10;
      }
      ++i;
      any = true;
    }
  }
  if (!any) return std::nullopt;
  while (i < s.size() && s[i] == ' ') ++i;
  std::string_view unit = s.substr(i);
  Ticks per = 0;
  if (unit == "s") per = kTicksPerSecond;
  else if (unit == "ms") per = kTicksPerMs;
  else if (unit == "us") per = kTicksPerUs;
  else if (unit == "ns") per = 0;  // handled below: 1 ns is not a whole tick count
  else if (unit == "min") per = 60 * kTicksPerSecond;
  else if (unit == "h") per = 3600 * kTicksPerSecond;
  else if (unit == "ticks") per = 1;
  else return std::nullopt;
  if (unit == "ns") {
    // 1 ns = 3.636 ticks: round to the nearest tick.
    if (whole > INT64_MAX / 3636) return std::nullopt;
    Wide t = static_cast<Wide>(whole) * 3636 * frac_div + static_cast<Wide>(frac) * 3636;
    return static_cast<Ticks>((t + 500 * frac_div) / (1000 * frac_div));
  }
  if (whole > INT64_MAX / per) return std::nullopt;
  Wide t = static_cast<Wide>(whole) * per + static_cast<Wide>(frac) * per / frac_div;
  if (t > INT64_MAX) return std::nullopt;
  return static_cast<Ticks>(t);
}

std::string format_duration(Ticks t) {
  char buf[64];
  const bool neg = t < 0;
  std::uint64_t a = neg ? static_cast<std::uint64_t>(-(t + 1)) + 1 : static_cast<std::uint64_t>(t);
  const char* sign = neg ? "-" : "";
  if (a >= static_cast<std::uint64_t>(kTicksPerSecond)) {
    std::uint64_t ms = a / static_cast<std::uint64_t>(kTicksPerMs);
    std::snprintf(buf, sizeof buf, "%s%llu.%03llu s", sign,
                  static_cast<unsigned long long>(ms / 1000), static_cast<unsigned long long>(ms % 1000));
  } else if (a >= static_cast<std::uint64_t>(kTicksPerMs)) {
    std::uint64_t us = a / static_cast<std::uint64_t>(kTicksPerUs);
    std::snprintf(buf, sizeof buf, "%s%llu.%03llu ms", sign,
                  static_cast<unsigned long long>(us / 1000), static_cast<unsigned long long>(us % 1000));
  } else {
    std::uint64_t ns = static_cast<std::uint64_t>(ticks_to_ns(static_cast<Ticks>(a)));
    std::snprintf(buf, sizeof buf, "%s%llu.%03llu us", sign,
                  static_cast<unsigned long long>(ns / 1000), static_cast<unsigned long long>(ns % 1000));
  }
  return buf;
}

}  // namespace pbvbus::bus
