#include "pbvbus/gateways/socketcand.hpp"

#include <array>
#include <cstdio>

namespace pbvbus::gateways::socketcand {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && is_space(s[i])) ++i;
    const std::size_t start = i;
    while (i < s.size() && !is_space(s[i])) ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

std::optional<std::uint32_t> hex(std::string_view s, std::size_t max_digits) {
  if (s.empty() || s.size() > max_digits) return std::nullopt;
  std::uint32_t v = 0;
  for (char c : s) {
    int d;
    if (c >= '0' && c <= '9') d = c - '0';
    else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
    else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    else return std::nullopt;
    v = (v << 4) | static_cast<std::uint32_t>(d);
  }
  return v;
}

Parsed fail(std::string msg) { return Parsed{std::nullopt, std::move(msg)}; }

Parsed parse_send(const std::vector<std::string_view>& w) {
  if (w.size() < 3) return fail("send needs an id and a dlc");
  const auto id = hex(w[1], 8);
  if (!id) return fail("send: the id must be 1..8 hex digits");
  // python-can 4.1 sends extended ids unpadded (§2.3): 8 digits OR a value beyond 11 bits.
  const bool ext = w[1].size() == 8 || *id > 0x7FF;
  if (*id > 0x1FFFFFFF) return fail("send: the id is beyond 29 bits");
  if (w[2].size() != 1 || w[2][0] < '0' || w[2][0] > '8') return fail("send: the dlc must be 0..8");
  const auto dlc = static_cast<std::uint8_t>(w[2][0] - '0');
  if (w.size() != 3u + dlc) return fail("send: the number of data bytes does not match the dlc");
  CanFrame f;
  f.id = *id;
  f.extended = ext;
  f.dlc = dlc;
  for (std::size_t i = 0; i < dlc; ++i) {
    const auto b = hex(w[3 + i], 2);
    if (!b) return fail("send: a data byte must be 1..2 hex digits");
    f.data[i] = static_cast<std::uint8_t>(*b);
  }
  return Parsed{Command{Op::Send, {}, f}, {}};
}

}  // namespace

Parsed parse_element(std::string_view content) {
  const auto w = words(content);
  if (w.empty()) return fail("empty element");
  const std::string_view cmd = w[0];
  const auto bare = [&](Op op) {
    return w.size() == 1 ? Parsed{Command{op, std::string(cmd), {}}, {}}
                         : fail(std::string(cmd) + " takes no argument");
  };
  if (cmd == "open") {
    if (w.size() != 2) return fail("open needs one bus name");
    return Parsed{Command{Op::Open, std::string(w[1]), {}}, {}};
  }
  if (cmd == "rawmode") return bare(Op::RawMode);
  if (cmd == "bcmmode") return bare(Op::BcmMode);
  if (cmd == "echo") return bare(Op::Echo);
  if (cmd == "send") return parse_send(w);
  static constexpr std::array<std::string_view, 9> kUnsupported{
      "controlmode", "statistics", "isotpmode", "add",        "update",
      "delete",      "filter",     "subscribe", "unsubscribe"};
  for (std::string_view u : kUnsupported)
    if (cmd == u) return Parsed{Command{Op::Unsupported, std::string(cmd), {}}, {}};
  return fail("unknown command");
}

std::string encode_frame(const CanFrame& f, bus::Ticks t) {
  if (t < 0) t = 0;
  const long long secs = static_cast<long long>(t / bus::kTicksPerSecond);
  const long long usecs = static_cast<long long>((t % bus::kTicksPerSecond) / bus::kTicksPerUs);
  char buf[64];
  const int n = f.extended
                    ? std::snprintf(buf, sizeof buf, "< frame %08X %lld.%06lld ",
                                    static_cast<unsigned>(f.id & 0x1FFFFFFFu), secs, usecs)
                    : std::snprintf(buf, sizeof buf, "< frame %03X %lld.%06lld ",
                                    static_cast<unsigned>(f.id & 0x7FFu), secs, usecs);
  std::string s(buf, static_cast<std::size_t>(n));
  if (!f.rtr) {
    for (unsigned i = 0; i < f.dlc && i < 8; ++i) {
      std::snprintf(buf, sizeof buf, "%02X", f.data[i]);
      s += buf;
    }
  }
  s += " >";
  return s;
}

std::string encode_error(std::string_view text) {
  std::string s = "< error ";
  for (char c : text) s += (c == '<' || c == '>') ? '?' : c;  // never a delimiter inside
  s += " >";
  return s;
}

void SocketcandSession::feed(std::string_view bytes, std::vector<std::string>& replies,
                             std::vector<CanFrame>& to_bus) {
  for (char c : bytes) {
    // The close rule is checked at every error, not once per feed(): a single read can hold an
    // endless run of errors (a 10 000-character element is 39 of them), and every byte after
    // the 8th one in a row is not read at all.
    if (wants_close()) return;
    switch (m_lex) {
      case Lex::Between:
        if (c == '<') {
          m_lex = Lex::InElement;
          m_element.clear();
        } else if (!is_space(c)) {
          m_lex = Lex::Garbage;
          m_run = 1;
          error("garbage outside an element", replies, true);
        }
        break;
      case Lex::Garbage:
        if (c == '<') {
          m_lex = Lex::InElement;
          m_element.clear();
        } else if (++m_run % kMaxElement == 0) {
          error("garbage outside an element", replies, true);
        }
        break;
      case Lex::InElement:
        if (c == '>') {
          m_lex = Lex::Between;
          handle(m_element, replies, to_bus);
          m_element.clear();
        } else if (m_element.size() >= kMaxElement) {
          m_lex = Lex::Discarding;
          m_run = m_element.size() + 1;
          m_element.clear();
          error("element too long", replies, true);
        } else {
          m_element += c;
        }
        break;
      case Lex::Discarding:
        if (c == '>') m_lex = Lex::Between;
        else if (++m_run % kMaxElement == 0) error("element too long", replies, true);
        break;
    }
  }
}

void SocketcandSession::error(std::string text, std::vector<std::string>& replies, bool garbage) {
  ++m_stats.errors;
  if (garbage) ++m_stats.garbage;
  ++m_consecutive_errors;
  replies.push_back(encode_error(text));
}

void SocketcandSession::handle(std::string_view content, std::vector<std::string>& replies,
                               std::vector<CanFrame>& to_bus) {
  ++m_stats.elements;
  const Parsed p = parse_element(content);
  if (!p.command) return error(p.error, replies, false);
  const Command& c = *p.command;
  switch (c.op) {
    case Op::Open:
      if (!m_channel.empty() && c.word != m_channel)
        return error("could not open bus " + c.word + " (this door serves " + m_channel + ")",
                     replies, false);
      m_mode = Mode::Bcm;
      break;
    case Op::RawMode:
    case Op::BcmMode:
      if (m_mode == Mode::Greeted) return error("no bus open", replies, false);
      m_mode = c.op == Op::RawMode ? Mode::Raw : Mode::Bcm;
      break;
    case Op::Send:
      if (m_mode == Mode::Greeted) return error("no bus open", replies, false);
      ++m_stats.frames_in;
      to_bus.push_back(c.frame);
      m_consecutive_errors = 0;
      return;  // socketcand answers nothing
    case Op::Echo:
      m_consecutive_errors = 0;
      replies.emplace_back(kEcho);
      return;
    case Op::Unsupported:
      return error(c.word + " is not supported by pbvbus (raw mode only)", replies, false);
  }
  m_consecutive_errors = 0;
  replies.emplace_back(kOk);
}

std::optional<std::string> SocketcandSession::frame_to_client(const CanFrame& f,
                                                              bus::Ticks now) const {
  if (m_mode != Mode::Raw) return std::nullopt;
  return ' ' + encode_frame(f, now);
}

}  // namespace pbvbus::gateways::socketcand
