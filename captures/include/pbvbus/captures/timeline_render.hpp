#pragma once
// Drawings of a Timeline (timeline.hpp) for `pbvbus timeline`: a self-contained interactive HTML
// page and a static SVG picture.
//
// HTML (to_html): one file, no network. The frame data is embedded as one JSON document in
// <script type="application/json" id="pbvbus-data">, compactly:
//   "origin"  absolute ns (a string, exact) of the page's time 0; every time below is relative
//   "span", "view"  [from, to] of the data and of the first view
//   "desc"    strings: the decoded description of a frame (describe()) and short box labels
//   "ent"     distinct frames: [hex octets, kind 0..4, desc index, label index]; kind indexes
//             token, request, response, SC, bad. Frames with the same octets, flags and comment
//             share one entry (tokens, polls and most replies repeat).
//   "lanes"   per lane: name, desc, speed, if; "t" frame starts as differences to the previous
//             start (sorted), "e" entry per frame; token spans "tk" (start differences), "tl"
//             (lengths), "th" holder, "tp" passed by; "dx" per DP slave: "a" address, "t" poll
//             times (differences), "c0" cycle of the first poll (-1 none), "m" masters, "un"
//             indices of unanswered polls
//   "ev"      events: [time, style, category, text]
//   "cpu"     CPU rows (docs/h-system.md): "states" and "roles" the names of the numbers; "rows" per CPU
//             "label" ("CPU 0 (rack 0)", with the system's name when several H systems are in
//             the capture), "sys", "r" rack, spans "s" [start, end, state, role] and OB marks
//             "ob" [time, OB number, event ID, reason, text]
//   "ac"      active channels: per switched station "a" and spans "s" [start, end, lane, line]
// A frame's end is worked out in the page from its octet count and the lane's speed exactly as
// frame_duration_ns() does. The script draws only the visible window: frames wider than a
// pixel one by one (labelled when wide enough), denser ones aggregated per pixel (colour of
// the kind with the largest share of the pixel's time, bad frames always visible, opacity by
// how busy the bus was). It zooms with the wheel, buttons or + / - down to ~100 ns, pans by
// dragging, arrows or buttons, shows a bit-time axis per lane once fewer than 6000 bit times of
// that lane are in view (a click on a frame makes its end the axis origin), tooltips for frames
// (decoded telegram, hex, time since the previous frame in µs and bit times), token spans, DP
// polls and events, and a table of DP cycle times for the polls in view. After each drawing the
// page sets data-rendered="1" on <body>; each lane is a <g class="lane" data-lane="NAME">.
// Below the lanes come the active-channel rows (one per switched station) and the CPU rows (one
// per CPU of an H system, <g class="cpu-row" data-rack="N">): spans coloured by state (a
// standby's lighter), labelled "RUN master" when wide enough, OB marks as ticks with the OB
// number (<g class="cpu-ob" data-ob="72">); <body> gets data-cpu-rows, data-cpu-spans-drawn and
// data-cpu-obs-drawn. RUN-Solo and RUN-Redundant are one state: the system mode is not a span.
// The CPU spans and OB marks have tooltips as the frames do.
//
// SVG (to_svg): the window of the Timeline as a static picture of `width` pixels, the same
// rows as the page, frames aggregated per pixel when denser than a pixel, <title> tooltips on
// frames drawn one by one, the active-channel and CPU rows with <title> tooltips on their spans
// and OB marks, a legend and a DP cycle summary below the lanes.
//
// Text from the capture (interface names, comments, event texts) is escaped for its context and
// invalid UTF-8 is replaced, so any capture gives well-formed XML and JSON.

#include <cstdint>
#include <optional>
#include <string>

#include "pbvbus/captures/timeline.hpp"

namespace pbvbus::captures {

struct TimelineHtmlOptions {
  std::string title;                      ///< shown in the page header (e.g. the file name)
  std::optional<std::int64_t> view_from_ns;  ///< first view; default: the Timeline's window
  std::optional<std::int64_t> view_to_ns;
  /// Shown under the header in <p id="note">, e.g. what a page of a long capture leaves out
  /// (timeline_window.hpp); nothing when empty.
  std::string note;
};
std::string to_html(const Timeline& tl, const TimelineHtmlOptions& opts = {});

struct TimelineSvgOptions {
  std::string title;
  int width = 1600;  ///< pixels; at least 600
};
std::string to_svg(const Timeline& tl, const TimelineSvgOptions& opts = {});

/// Replaces invalid UTF-8 sequences and control characters other than \n and \t by U+FFFD.
std::string sanitize_utf8(std::string_view s);

}  // namespace pbvbus::captures
