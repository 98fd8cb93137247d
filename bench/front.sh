#!/usr/bin/env bash
# The front end with the pre-flight analyses on (docs/BENCHMARKS.md, "Pre-flight analyses
# at scale"):
#   1. `aviary bench front` in one process: the realistic mission of 5 and 20 MB, N
#      statements in one SEQUENTIAL block, and a chain of capabilities; each run is the
#      whole of `aviary check` minus reading and printing, and the median is printed.
#   2. `aviary check FILE` as a user runs it, one process per run, on the same missions
#      written to files (reading and printing included): CPU and wall time, the fastest of
#      RUNS. With BASE_BINARY, each run of it comes right after the same run of the new
#      build, so both see the same machine.
#
#   bench/front.sh [RUNS] [BASE_BINARY]      default 3 runs
#
# Builds Aviary in release mode. Each size runs under `timeout` (600 s), so a quadratic
# build still finishes the script. Prints the machine's CPU first.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-3}
BASE=${2:-}
cargo build --release -q -p aviary-cli
AVIARY=target/release/aviary
lscpu | grep -E '^(Model name|CPU\(s\)|Thread|CPU max MHz|BogoMIPS)' || true
uptime

echo "### 1. in one process (aviary bench front)"
for mb in 5 20; do
    echo "== realistic, $mb MB"
    timeout 600 "$AVIARY" bench front --shape realistic --n "$mb" --runs "$RUNS" | tail -1 || echo "(stopped after 600 s or failed)"
done
for n in 20000 80000 1500000; do
    echo "== sequential, $n statements"
    timeout 600 "$AVIARY" bench front --shape sequential --n "$n" --runs "$RUNS" | tail -1 || echo "(stopped after 600 s or failed)"
done
echo "== chain, 50000 capabilities"
timeout 600 "$AVIARY" bench front --shape chain --n 50000 --runs "$RUNS" | tail -1 || echo "(stopped after 600 s or failed)"

echo "### 2. aviary check FILE, one process per run"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
emit() { # NAME SHAPE N
    "$AVIARY" bench front --shape "$2" --n "$3" --emit >"$work/$1.mission"
    "$AVIARY" bench front --shape "$2" --n "$3" --emit-world >"$work/$1.world.toml"
}
emit realistic5 realistic 5
emit realistic20 realistic 20
emit sequential sequential 1500000
emit chain chain 50000
# The fastest of RUNS: CPU (user + system) and wall seconds, from GNU time.
fastest() { # BINARY MISSION
    local best_cpu="" best_wall=""
    for _ in $(seq "$RUNS"); do
        /usr/bin/time -o "$work/time" -f "%U %S %e" timeout 600 "$1" check "$2" >/dev/null 2>&1 || true
        read -r cpu wall < <(tail -1 "$work/time" | awk '{print $1 + $2, $3}')
        if [[ -z $best_cpu ]] || awk "BEGIN {exit !($cpu < $best_cpu)}"; then best_cpu=$cpu; fi
        if [[ -z $best_wall ]] || awk "BEGIN {exit !($wall < $best_wall)}"; then best_wall=$wall; fi
    done
    echo "$best_cpu $best_wall"
}
for m in realistic5 realistic20 sequential chain; do
    size=$(stat -c %s "$work/$m.mission")
    for bin in "$AVIARY" ${BASE:+"$BASE"}; do
        read -r cpu wall < <(fastest "$bin" "$work/$m.mission")
        awk -v m="$m" -v b="$bin" -v s="$size" -v c="$cpu" -v w="$wall" \
            'BEGIN {printf "%-12s %-28s %6.2f MB  cpu %6.3f s (%5.1f MB/s)  wall %6.3f s (%5.1f MB/s)\n", m, b, s/1e6, c, s/1e6/c, w, s/1e6/w}'
    done
done
