#!/bin/bash
# Plots autograsp-frame-cost's JSON: added time per frame (p50, p99, max) by phase and object, log
# scale, with the 0.5 ms (p99) and 2 ms (max) budgets. Usage: plot.sh RESULT.json OUT.png
set -euo pipefail
json=$1 out=$2
data=$(mktemp)
trap 'rm -f "$data"' EXIT
python3 - "$json" > "$data" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
phases = ["open", "grab", "held", "held_moving", "held_deforming"]
i = 0
for m in d["meshes"]:
    if not m["ok"]:
        continue
    for p in phases:
        a = m["phases"][p]
        print(i, '"%s %s"' % (m["name"].replace("stanford-", "").replace("-subdiv", ""), p),
              max(a["added_p50_ms"], 1e-3), max(a["added_p99_ms"], 1e-3), max(a["added_max_ms"], 1e-3))
        i += 1
    i += 1
PY
gnuplot <<GP
set terminal pngcairo size 1400,600 font "sans,9"
set output "$out"
set termoption noenhanced
set logscale y
set yrange [0.001:100]
set ylabel "time added per frame (ms)"
set xtics rotate by 60 right
set key top left
set grid ytics
set style fill solid 0.8
plot "$data" using 1:3:xtic(2) with points pt 7 ps 1.2 title "p50", \
     "" using 1:4 with points pt 5 ps 1.2 title "p99", \
     "" using 1:5 with points pt 2 ps 1.5 title "max", \
     0.5 with lines dt 2 lc rgb "orange" title "p99 budget 0.5 ms", \
     2 with lines dt 2 lc rgb "red" title "max budget 2 ms"
GP
