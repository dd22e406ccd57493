#!/usr/bin/env python3
# Runs two builds of pbvbus_bench side by side (docs/benchmarks.md, "Twice the simulation
# speed"): ROUNDS rounds, in each both binaries back to back on the same filter, the order
# alternating; prints every run and the medians and ratios (new / base) of the counters.
#   BASE=/path/to/old/pbvbus_bench NEW=build/bin/pbvbus_bench bench/sidebyside.py FILTER [ROUNDS] [MIN_TIME]
import json, subprocess, statistics, sys, os
base = os.environ.get('BASE', 'base/build/bin/pbvbus_bench')
new = os.environ.get('NEW', 'build/bin/pbvbus_bench')
filt = sys.argv[1]
rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 5
mintime = sys.argv[3] if len(sys.argv) > 3 else '2'
res = {'base': {}, 'new': {}}
for r in range(rounds):
    for name, binp in (('base', base), ('new', new)) if r % 2 == 0 else (('new', new), ('base', base)):
        out = subprocess.run([binp, '--benchmark_filter=' + filt, '--benchmark_min_time=' + mintime,
                              '--benchmark_format=json'], capture_output=True, text=True).stdout
        d = json.loads(out)
        la = os.getloadavg()[0]
        for b in d['benchmarks']:
            row = {k: v for k, v in b.items() if isinstance(v, (int, float)) and k not in ('repetitions','repetition_index','threads','family_index','per_family_instance_index')}
            res[name].setdefault(b['name'], []).append(row)
            print(f"round {r} {name:4} {b['name']}: " + ' '.join(f"{k}={row[k]:.4g}" for k in sorted(row) if k in ('virt_s_per_cpu_s','virt_s_per_wall_s','cpu_ns_per_frame','lag_min_us','lag_median_us','lag_p99_us','lag_max_us','report_max_lag_us','late_wakeups','cpu_share','samples','maxrss_mb','heap_mb','frames_per_s')) + f"  load={la:.1f}", flush=True)
print()
for bname in res['new']:
    keys = [k for k in res['new'][bname][0] if k.startswith('virt_s') or k.startswith('lag_') or k in ('cpu_ns_per_frame','frames_per_s','maxrss_mb','heap_mb','dp_cycle_us','cpu_share','report_max_lag_us')]
    for k in keys:
        try:
            b = statistics.median(x[k] for x in res['base'][bname]); n = statistics.median(x[k] for x in res['new'][bname])
        except (KeyError, statistics.StatisticsError):
            continue
        print(f"{bname} {k}: base median {b:.4g}  new median {n:.4g}  ratio new/base {(n/b if b else float('nan')):.3f}")
