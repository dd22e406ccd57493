// Comparison of the replayed replies with the recorded ones, and the mask rules (replay.hpp).

#include <algorithm>
#include <charconv>

#include "pbvbus/conformance/replay.hpp"
#include "pbvbus/dp/sap.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::conformance {

namespace {

template <class T>
bool parse_uint(std::string_view s, T max, T& out) {
  unsigned long long v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || s.empty() || v > max) return false;
  out = static_cast<T>(v);
  return true;
}

std::vector<std::string_view> split(std::string_view s, char c) {
  std::vector<std::string_view> parts;
  std::size_t b = 0;
  for (std::size_t i = 0; i <= s.size(); ++i)
    if (i == s.size() || s[i] == c) {
      parts.push_back(s.substr(b, i - b));
      b = i + 1;
    }
  return parts;
}

bool parse_range(std::string_view s, std::size_t& first, std::size_t& last) {
  const auto dash = s.find('-');
  if (dash == std::string_view::npos) {
    if (!parse_uint<std::size_t>(s, fdl::kMaxDu, first)) return false;
    last = first;
    return true;
  }
  return parse_uint<std::size_t>(s.substr(0, dash), fdl::kMaxDu, first) &&
         parse_uint<std::size_t>(s.substr(dash + 1), fdl::kMaxDu, last) && first <= last;
}

struct Decoded {
  bool ok = false;
  fdl::Telegram t;
  std::size_t du_offset = 0;
};

Decoded decode(const std::vector<std::uint8_t>& b) {
  Decoded d;
  d.ok = fdl::decode(b, d.t) == fdl::DecodeError::None;
  if (d.ok && !d.t.data.empty()) d.du_offset = static_cast<std::size_t>(d.t.data.data() - b.data());
  return d;
}

bool is_data_exchange(const ReplayFrame& q) {
  const auto fn = fdl::fc_request_fn(q.fc);
  return !q.dsap && (fn == fdl::RequestFn::SrdLow || fn == fdl::RequestFn::SrdHigh);
}

/// Whether DU offset `k` of the reply to `q` is masked by `m`.
bool masked(const ReplayMask& m, const ReplayFrame& q, std::size_t k) {
  switch (m.kind) {
    case ReplayMask::Kind::Inputs:
      return is_data_exchange(q) || (q.dsap && *q.dsap == dp::kSapRdInp);
    case ReplayMask::Kind::DiagExt:
      return q.dsap && *q.dsap == dp::kSapSlaveDiag && k >= 6;
    case ReplayMask::Kind::Octets:
      if (q.da != m.station) return false;
      if (m.sap ? !(q.dsap && *q.dsap == *m.sap) : !is_data_exchange(q)) return false;
      return k >= m.first && k <= m.last;
  }
  return false;
}

}  // namespace

const char* diff_kind_name(DiffKind k) {
  switch (k) {
    case DiffKind::MissingReply: return "missing reply";
    case DiffKind::ExtraReply: return "extra reply";
    case DiffKind::OtherFc: return "other FC";
    case DiffKind::OtherData: return "other data";
    case DiffKind::Timing: return "timing";
  }
  return "?";
}

const char* diff_kind_key(DiffKind k) {
  switch (k) {
    case DiffKind::MissingReply: return "missing_reply";
    case DiffKind::ExtraReply: return "extra_reply";
    case DiffKind::OtherFc: return "other_fc";
    case DiffKind::OtherData: return "other_data";
    case DiffKind::Timing: return "timing";
  }
  return "?";
}

std::optional<ReplayMask> parse_replay_mask(const std::string& rule, std::string& error) {
  ReplayMask m;
  m.text = rule;
  if (rule == "inputs") {
    m.kind = ReplayMask::Kind::Inputs;
    return m;
  }
  if (rule == "diag-ext") {
    m.kind = ReplayMask::Kind::DiagExt;
    return m;
  }
  auto parts = split(rule, ':');
  bool ok = false;
  if (parts.size() == 3 && parts[0] == "counter") {
    ok = parse_uint<std::uint8_t>(parts[1], 126, m.station) && parse_range(parts[2], m.first, m.last);
  } else if (parts.size() == 3) {
    std::uint8_t sap = 0;
    ok = parse_uint<std::uint8_t>(parts[0], 126, m.station) && parse_range(parts[2], m.first, m.last);
    if (parts[1] != "dx") {
      ok = ok && parse_uint<std::uint8_t>(parts[1], 63, sap);
      m.sap = sap;
    }
  }
  if (!ok) {
    error = "bad mask '" + rule +
            "': expected inputs, diag-ext, counter:ADDR:OFFSET[-END] or ADDR:SAP:OFFSET[-END] "
            "(SAP 0..63 or dx; ADDR 0..126; DU offsets from 0)";
    return std::nullopt;
  }
  return m;
}

ReplayResult compare_replay(const ReplayInput& in, const Replayer& rp, const ReplayCompareOptions& o) {
  ReplayResult res;
  res.line = in.line;
  res.baud = in.baud;
  res.station = rp.options().station;
  res.pacing = rp.options().pacing;
  res.min_tsdr = o.min_tsdr;
  res.max_tsdr = o.max_tsdr != 0 ? o.max_tsdr : fdl::BusParams::defaults(in.baud).max_tsdr;
  res.recorded_frames = in.frames.size();
  res.pacing_slips = rp.pacing_slips();
  res.read_error = in.read_error;
  for (const ReplayFrame& f : in.frames)
    if (f.role == ReplayRole::Unusable) res.unusable.push_back(&f);
  std::vector<std::size_t> mask_hits(o.masks.size(), 0);

  const auto& sent = rp.sent();
  const auto& heard = rp.heard();
  std::size_t h = 0;
  const bus::Ticks bit = bus::ticks_per_bit(in.baud);
  for (std::size_t s = 0; s < sent.size(); ++s) {
    const ReplayFrame& q = in.frames[sent[s].frame];
    if (q.role == ReplayRole::Token) ++res.tokens_replayed;
    else ++res.requests_replayed;
    // Frames heard after this one and before the next sent frame.
    while (h < heard.size() && heard[h].start < sent[s].end) ++h;
    const bus::Ticks until = s + 1 < sent.size() ? sent[s + 1].start : INT64_MAX;
    std::vector<const Replayer::Heard*> got;
    while (h < heard.size() && heard[h].start < until) got.push_back(&heard[h++]);

    ReplayDiff base;
    base.frame = sent[s].frame;
    base.time = q.start;
    base.station = q.da;
    base.service = replay_service_name(q);
    base.request = q.bytes;
    const bool expects = q.role == ReplayRole::Request && q.expects_reply;
    const ReplayFrame* rec = expects && q.reply >= 0 ? &in.frames[static_cast<std::size_t>(q.reply)] : nullptr;
    auto add = [&](DiffKind k, const Replayer::Heard* rep) {
      ReplayDiff d = base;
      d.kind = k;
      if (rec) d.recorded = rec->bytes;
      if (rep) {
        d.replayed = rep->bytes;
        d.tsdr_bits = (rep->start - sent[s].end) / bit;
      }
      res.by_kind[static_cast<int>(k)]++;
      res.diffs.push_back(std::move(d));
      return &res.diffs.back();
    };
    if (!expects) {
      for (const auto* g : got) add(DiffKind::ExtraReply, g);
      continue;
    }
    if (q.reply_unusable) {
      ++res.not_compared_unusable;
      continue;
    }
    ++res.compared;
    const std::size_t before = res.diffs.size();
    const Replayer::Heard* rep = got.empty() ? nullptr : got.front();
    if (rec && !rep) {
      add(DiffKind::MissingReply, nullptr);
    } else if (!rec && rep) {
      add(DiffKind::ExtraReply, rep);
    } else if (rec && rep) {
      const Decoded dr = decode(rec->bytes);
      const Decoded dp = decode(rep->bytes);
      const bool other_fc = !dp.ok || rec->bytes.empty() || rep->bytes.empty() ||
                            rec->bytes[0] != rep->bytes[0] || dr.t.fc != dp.t.fc;
      if (other_fc) {
        ReplayDiff* d = add(DiffKind::OtherFc, rep);
        const std::size_t n = std::max(rec->bytes.size(), rep->bytes.size());
        for (std::size_t k = 0; k < n; ++k)
          if (k >= rec->bytes.size() || k >= rep->bytes.size() || rec->bytes[k] != rep->bytes[k])
            d->frame_offsets.push_back(k);
      } else {
        // Same frame type and FC: compare octet by octet, DU octets under the masks.
        std::vector<std::size_t> off, du_off;
        bool any_masked = false;
        const std::size_t n = std::max(rec->bytes.size(), rep->bytes.size());
        const std::size_t du_end = dr.du_offset + dr.t.data.size();
        for (std::size_t k = 0; k < n; ++k) {
          const bool differs =
              k >= rec->bytes.size() || k >= rep->bytes.size() || rec->bytes[k] != rep->bytes[k];
          if (!differs) continue;
          const bool in_du = dr.t.data.size() > 0 && k >= dr.du_offset && k < du_end &&
                             rec->bytes.size() == rep->bytes.size();
          if (in_du) {
            bool m = false;
            for (std::size_t i = 0; i < o.masks.size(); ++i)
              if (masked(o.masks[i], q, k - dr.du_offset)) {
                m = true;
                ++mask_hits[i];
                break;
              }
            if (m) {
              any_masked = true;
              continue;
            }
            du_off.push_back(k - dr.du_offset);
          }
          off.push_back(k);
        }
        // The FCS (second last octet of a frame with an FC) follows a masked DU.
        if (any_masked && du_off.empty() && rec->bytes.size() >= 2 &&
            rec->bytes.size() == rep->bytes.size()) {
          const std::size_t fcs_at = rec->bytes.size() - 2;
          off.erase(std::remove(off.begin(), off.end(), fcs_at), off.end());
        }
        if (!off.empty()) {
          ReplayDiff* d = add(DiffKind::OtherData, rep);
          d->frame_offsets = std::move(off);
          d->du_offsets = std::move(du_off);
        }
      }
    }
    if (rec && rep) {
      const std::int64_t tsdr = (rep->start - sent[s].end) / bit;
      if (tsdr < static_cast<std::int64_t>(res.min_tsdr) || tsdr > static_cast<std::int64_t>(res.max_tsdr))
        add(DiffKind::Timing, rep);
    }
    for (std::size_t k = 1; k < got.size(); ++k) add(DiffKind::ExtraReply, got[k]);
    if (res.diffs.size() == before) ++res.matches;
  }
  for (std::size_t i = 0; i < o.masks.size(); ++i) res.masks.emplace_back(o.masks[i].text, mask_hits[i]);
  return res;
}

int replay_exit_status(const ReplayResult& r) { return r.diffs.empty() ? 0 : 1; }

}  // namespace pbvbus::conformance
