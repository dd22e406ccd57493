#pragma once
// The style sheet and the script of the timeline HTML page (timeline_page.cpp), kept apart from
// the C++ that writes the data so that each can be read on its own.

namespace pbvbus::captures::detail {

/// CSS of the page.
extern const char* const kTimelineCss;
/// The page script: reads the JSON in <script id="pbvbus-data">, draws the SVG for the view,
/// handles zoom, pan, tooltips and the DP cycle table. Below the lanes, one row per switched
/// station ("ac" in the data: spans [start, end, lane, line]) in the colour of its active
/// channel's lane, hatched where it has none: <g class="active-channel" data-station="N"> with
/// <rect class="ac-span">; <body data-active-rows> counts the rows. Plain ES2017, no network,
/// no libraries.
extern const char* const kTimelineJs;

}  // namespace pbvbus::captures::detail
