#!/bin/bash
# Same behaviour, two binaries: runs the examples that exercise the line, the DP, switched I/O,
# the H-system and the links, and benchmark cases (a) and (c) as 500 ms scenarios, with both
# `pbvbus` binaries, then compares the captures byte for byte (cmp) and the JSON reports with
# the figures that may differ masked: wall time, speed, and the scheduler's event count (a
# count of the simulator's own work, not of the bus's).
#   bench/identity/same_output.sh OLD_PBVBUS NEW_PBVBUS [OUTDIR]
# Exit status 0 when everything is the same.
set -u
old=$1; new=$2; out=${3:-$(mktemp -d)}
here=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out/old" "$out/new"
status=0
run() {  # BIN DIR NAME FILE [ARGS...]
  local bin=$1 dir=$2 name=$3 file=$4; shift 4
  "$bin" run "$file" --fast --quiet --capture "$dir/$name.pcapng" --json "$@" >"$dir/$name.json" 2>"$dir/$name.err"
}
mask() {
  /usr/bin/python3 -c '
import json, sys
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in ("wall_s", "wall_time_s", "speed", "events", "virt_s_per_wall_s")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open(sys.argv[1]))), indent=1, sort_keys=True))' "$1"
}
for x in dp-basic dp-faults dp-line multimaster switched-io h-system y-link dp-pa-link; do
  run "$old" "$out/old" "$x" "$here/examples/$x.textproto"
  run "$new" "$out/new" "$x" "$here/examples/$x.textproto"
done
for x in case-a case-c; do
  run "$old" "$out/old" "$x" "$here/bench/identity/$x.textproto" --duration 500ms
  run "$new" "$out/new" "$x" "$here/bench/identity/$x.textproto" --duration 500ms
done
for f in "$out"/new/*.pcapng; do
  n=$(basename "$f" .pcapng)
  if cmp -s "$out/old/$n.pcapng" "$f" && diff -q <(mask "$out/old/$n.json") <(mask "$out/new/$n.json") >/dev/null; then
    echo "$n: same"
  else
    echo "$n: DIFFERENT (see $out/old and $out/new)"; status=1
  fi
done
exit $status
