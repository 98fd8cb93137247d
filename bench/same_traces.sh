#!/usr/bin/env bash
# Runs the same missions with two builds of aviary and compares their traces byte for byte:
# the paper's mission, the five fault drills, a 40-drone swarm whose cells are close
# enough for separation and planning to act, and W(40, 3). An optimisation must leave
# every one of them identical.
#   bench/same_traces.sh BASE_BINARY NEW_BINARY
set -euo pipefail
base=${1:?usage: same_traces.sh BASE_BINARY NEW_BINARY}
new=${2:?usage: same_traces.sh BASE_BINARY NEW_BINARY}
here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$new" bench swarm --drones 40 --emit >"$work/swarm.mission"
# Cells 300 m apart become 100 m apart: neighbours within the planner's reach.
"$new" bench swarm --drones 40 --emit-world | python3 -c '
import re, sys
def squeeze(m):
    v = int(m.group(0)); return str((v // 300) * 100 + v % 300)
for line in sys.stdin:
    if line.startswith(("Cell_", "home", "at")):
        line = re.sub(r"\d+", squeeze, line.split("=", 1)[1]).join([line.split("=", 1)[0] + "=", ""])
    sys.stdout.write(line)
' >"$work/swarm.world.toml"
"$new" bench w --n 40 --k 3 --emit >"$work/w.mission"
"$new" bench w --n 40 --k 3 --emit-world >"$work/w.world.toml"

missions=("$here/examples/search_and_rescue.mission" "$here"/examples/faults/*.mission "$work/swarm.mission" "$work/w.mission")
status=0
for m in "${missions[@]}"; do
    name=$(basename "$m" .mission)
    "$base" run "$m" --quiet --trace "$work/$name.base.jsonl" || true
    "$new" run "$m" --quiet --trace "$work/$name.new.jsonl" || true
    lines=$(wc -l <"$work/$name.base.jsonl")
    if cmp -s "$work/$name.base.jsonl" "$work/$name.new.jsonl"; then
        echo "same      $name ($lines events)"
    else
        echo "DIFFERENT $name"; status=1
        diff <(head -c 100000000 "$work/$name.base.jsonl") "$work/$name.new.jsonl" | head -5 || true
    fi
done
exit $status
