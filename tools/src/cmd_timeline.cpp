// `pbvbus timeline CAPTURE [-o FILE.html|FILE.svg] [--from T] [--to T] [--max-frames N]`: a picture of the bus
// (README.md "A picture of the bus"): lanes of frames, token holders, DP cycles and events of a pcapng capture, as a
// self-contained interactive HTML page or a static SVG. The model is captures/timeline.hpp, the
// drawings captures/timeline_render.hpp; this file is only the command line around them.
//
// Decisions:
//  - The output type follows the extension of -o (.html/.htm or .svg, any case); without -o the
//    HTML goes to stdout. Another extension is a usage error rather than a guess.
//  - HTML carries the whole capture and opens at --from/--to (so one can zoom out of the
//    window); SVG is a picture of exactly the window.
//  - Except for a long capture: an HTML page holds at most --max-frames frames (default
//    captures::kDefaultMaxPageFrames, 0 = no limit): the frames of a window starting at --from,
//    with the events and rows of the whole capture (captures/timeline_window.hpp); the page and
//    stderr say what was left out, exit 0.
//  - T is a duration with a unit (2s, 1500ms, 250us, 100ns, 1.25s), measured on the capture's
//    own clock (virtual time since the start of the run for pbvbus captures).
//  - Bad input (no pcapng, truncated, empty, no line interface, --from not before --to, a bad
//    duration) prints one line "pbvbus timeline: ..." on stderr, nothing on stdout and no
//    output file, exit 2.

#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <ostream>
#include <string>
#include <system_error>

#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/captures/timeline_render.hpp"
#include "pbvbus/captures/timeline_window.hpp"
#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {

namespace {

constexpr const char* kTimelineUsage =
    "usage: pbvbus timeline CAPTURE [-o FILE.html|FILE.svg] [--from T] [--to T] [--max-frames N]\n"
    "\n"
    "Draws a pcapng capture: one lane per line interface (or per probe interface) with every\n"
    "frame from its first start bit to its last stop bit, coloured by type (token, request,\n"
    "response, SC, bad), who held the token, the DP cycle of each slave answering\n"
    "Data_Exchange, and the recorded events and injected faults as vertical markers.\n"
    "\n"
    "  -o, --output FILE  write FILE; .html: an interactive page (zoom down to bit times,\n"
    "                     pan, tooltips with the decoded telegram; self-contained, no network),\n"
    "                     .svg: a static picture of the window. Default: HTML on stdout.\n"
    "  --from T, --to T   the window, e.g. --from 1.99s --to 2.05s (units s, ms, us, ns);\n"
    "                     default the whole capture. The HTML holds the whole capture (up\n"
    "                     to --max-frames frames) and opens at the window.\n"
    "  --max-frames N     HTML of a longer capture: hold only a window of at most N frames\n"
    "                     from --from on (default 50000, about 1.5 MB; 0: everything); the\n"
    "                     page and stderr say what was left out.\n"
    "  --help             this text\n"
    "\n"
    "Exit status: 0 success, 2 bad usage or a file that cannot be read as pcapng.\n";

enum class Format { Html, Svg };

std::optional<Format> format_of(const std::string& path) {
  const auto dot = path.rfind('.');
  if (dot == std::string::npos) return std::nullopt;
  std::string ext = path.substr(dot + 1);
  for (char& ch : ext)
    if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
  if (ext == "html" || ext == "htm") return Format::Html;
  if (ext == "svg") return Format::Svg;
  return std::nullopt;
}

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

int cmd_timeline(const Args& args, std::ostream& out, std::ostream& err) {
  std::string path, output;
  std::optional<std::int64_t> from, to;
  std::uint64_t max_frames = captures::kDefaultMaxPageFrames;
  auto usage_error = [&](const std::string& msg) {
    err << "pbvbus timeline: " << msg << "\nTry 'pbvbus timeline --help'.\n";
    return 2;
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      out << kTimelineUsage;
      return 0;
    }
    if (a == "--max-frames") {
      const std::string v = i + 1 < args.size() ? args[++i] : "";
      const auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), max_frames);
      if (v.empty() || ec != std::errc{} || p != v.data() + v.size())
        return usage_error("--max-frames needs a number of frames, e.g. --max-frames 20000 (0: no limit)");
      continue;
    }
    if (a == "-o" || a == "--output" || a == "--from" || a == "--to") {
      if (i + 1 >= args.size() || args[i + 1].empty())
        return usage_error(a + (a == "-o" || a == "--output"
                                    ? " needs a file name ending in .html or .svg"
                                    : " needs a time, e.g. " + a + " 2s"));
      const std::string& v = args[++i];
      if (a == "-o" || a == "--output") {
        output = v;
      } else {
        const auto ns = captures::parse_time_ns(v);
        if (!ns)
          return usage_error("bad time '" + v + "' for " + a +
                             " (expected a number and a unit: s, ms, us, ns, e.g. 1500ms)");
        (a == "--from" ? from : to) = *ns;
      }
    } else if (a.size() > 1 && a[0] == '-') {
      return usage_error("unknown option '" + a + "'");
    } else if (path.empty()) {
      path = a;
    } else {
      return usage_error("more than one capture given ('" + path + "', '" + a + "')");
    }
  }
  if (path.empty()) return usage_error("no capture file given");
  if (from && to && *from >= *to)
    return usage_error("--from " + captures::format_time_ns(*from) + " is not before --to " +
                       captures::format_time_ns(*to));
  Format format = Format::Html;
  if (!output.empty()) {
    const auto f = format_of(output);
    if (!f) return usage_error("cannot tell the output type of '" + output + "': use .html or .svg");
    format = *f;
  }

  std::string error;
  captures::TimelineOptions opts;
  if (format == Format::Svg) {
    opts.from_ns = from;
    opts.to_ns = to;
  }
  auto tl = captures::read_timeline_file(path, opts, error);
  if (!tl) {
    err << "pbvbus timeline: " << path << ": " << error << "\n";
    return 2;
  }
  std::string doc;
  if (format == Format::Svg) {
    captures::TimelineSvgOptions so;
    so.title = base_name(path);
    doc = captures::to_svg(*tl, so);
  } else {
    // The page holds everything and opens at the window; check the window against the capture
    // the same way the SVG would.
    if (from || to) {
      captures::TimelineOptions check;
      check.from_ns = from.value_or(tl->from_ns);
      check.to_ns = to.value_or(tl->to_ns);
      if (*check.from_ns >= *check.to_ns) {
        err << "pbvbus timeline: " << path << ": the window start "
            << captures::format_time_ns(*check.from_ns) << " is not before its end "
            << captures::format_time_ns(*check.to_ns) << " (the capture ends at "
            << captures::format_time_ns(tl->last_ns) << ")\n";
        return 2;
      }
    }
    captures::TimelineHtmlOptions ho;
    ho.title = base_name(path);
    const captures::PageWindow pw = captures::page_window(*tl, from, to, max_frames);
    if (pw.cut) {
      // A long capture: the frames of the window only; the overview (events, active channels,
      // CPU rows, Quantum rows) and the page's span stay whole (timeline_window.hpp).
      ho.note = captures::page_window_note(*tl, pw, max_frames);
      captures::TimelineOptions wo;
      wo.from_ns = pw.from_ns;
      wo.to_ns = pw.to_ns;
      auto part = captures::read_timeline_file(path, wo, error);
      if (!part) {
        err << "pbvbus timeline: " << path << ": " << error << "\n";
        return 2;
      }
      part->from_ns = tl->from_ns;
      part->to_ns = tl->to_ns;
      part->events = std::move(tl->events);
      part->active_channels = std::move(tl->active_channels);
      part->cpu_states = std::move(tl->cpu_states);
      part->cpu_obs = std::move(tl->cpu_obs);
      part->hsby_states = std::move(tl->hsby_states);
      part->hsby_switchovers = std::move(tl->hsby_switchovers);
      tl = std::move(part);
      err << "pbvbus timeline: " << ho.note << "\n";
    }
    ho.view_from_ns = from;
    ho.view_to_ns = to;
    if (from && !to) ho.view_to_ns = tl->to_ns;
    if (to && !from) ho.view_from_ns = tl->from_ns;
    doc = captures::to_html(*tl, ho);
  }
  if (output.empty()) {
    out << doc;
    return 0;
  }
  std::ofstream f(output, std::ios::binary | std::ios::trunc);
  if (f) f.write(doc.data(), static_cast<std::streamsize>(doc.size()));
  f.close();
  if (!f) {
    std::error_code ec;
    std::filesystem::remove(output, ec);
    err << "pbvbus timeline: cannot write " << output << "\n";
    return 2;
  }
  return 0;
}

}  // namespace pbvbus::tools
