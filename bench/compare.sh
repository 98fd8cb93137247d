#!/usr/bin/env bash
# Runs W(N, K) side by side: the paper's Go design (bench/anchors/go) and Aviary's
# `aviary bench w` (the same workload written in the language, through the whole
# pipeline), pair by pair in alternation so that both see the same machine load.
# Prints each pair, then the medians of wall time and peak RSS, and Aviary / Go.
#
#   bench/compare.sh [N] [K] [PAIRS]      defaults: 100000 10 7
#
# Installs Debian's golang-go when `go` is absent (needs root or sudo). Builds the Go
# anchor in a temporary directory outside the repository and Aviary in release mode.
# Wall time is the shell's clock around each process; peak RSS is GNU time's `%M` when
# installed, else the programs' own VmHWM report (Aviary prints it; Go's is then unknown).
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-100000}
K=${2:-10}
PAIRS=${3:-7}
ANCHOR=${ANCHOR:-bench/anchors/go}

if ! command -v go >/dev/null 2>&1; then
    echo "installing golang-go (Debian) ..." >&2
    SUDO=$([ "$(id -u)" = 0 ] && echo "" || echo sudo)
    $SUDO apt-get update -qq && $SUDO apt-get install -y -qq golang-go >/dev/null
fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cp "$ANCHOR"/go.mod "$ANCHOR"/main.go "$WORK"/
(cd "$WORK" && GOFLAGS=-mod=mod go build -o w .)
cargo build --release -q -p aviary-cli
AVIARY=target/release/aviary

# One run: prints "wall_seconds peak_kib".
measure() {
    if [ -x /usr/bin/time ]; then
        local start end
        start=$(date +%s%N)
        /usr/bin/time -f "%M" -o "$WORK/t" "$@" >"$WORK/out" 2>&1 || { cat "$WORK/out" >&2; exit 1; }
        end=$(date +%s%N)
        echo "$(awk -v s="$start" -v e="$end" 'BEGIN {printf "%.3f", (e - s) / 1e9}') $(cat "$WORK/t")"
    else
        local start end
        start=$(date +%s.%N)
        "$@" >"$WORK/out" 2>&1 || { cat "$WORK/out" >&2; exit 1; }
        end=$(date +%s.%N)
        # Without GNU time only Aviary reports its peak (VmHWM); Go's shows as 0.
        echo "$(awk -v s="$start" -v e="$end" 'BEGIN {printf "%.3f", e - s}') $(grep -o 'peak=[0-9.]*' "$WORK/out" | cut -d= -f2 | awk '{print int($1*1024)}' | grep . || echo 0)"
    fi
    grep -q 'ok=true' "$WORK/out" || { echo "a run did not check out:" >&2; cat "$WORK/out" >&2; exit 1; }
}

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

echo "W(N=$N, K=$K), $PAIRS pairs, whole process; machine: $(nproc) CPUs, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
printf '%-6s %12s %12s   %12s %12s\n' pair "go s" "go MiB" "aviary s" "aviary MiB"
# A warm-up of each, not counted.
measure "$WORK/w" "$N" "$K" >/dev/null
measure "$AVIARY" bench w --n "$N" --k "$K" >/dev/null
: >"$WORK/go"; : >"$WORK/av"
for i in $(seq 1 "$PAIRS"); do
    # Alternate which one goes first.
    if [ $((i % 2)) = 1 ]; then
        g=$(measure "$WORK/w" "$N" "$K"); a=$(measure "$AVIARY" bench w --n "$N" --k "$K")
    else
        a=$(measure "$AVIARY" bench w --n "$N" --k "$K"); g=$(measure "$WORK/w" "$N" "$K")
    fi
    echo "$g" >>"$WORK/go"; echo "$a" >>"$WORK/av"
    printf '%-6s %12s %12.1f   %12s %12.1f\n' "$i" "$(echo "$g" | cut -d' ' -f1)" "$(echo "$g" | awk '{print $2/1024}')" \
        "$(echo "$a" | cut -d' ' -f1)" "$(echo "$a" | awk '{print $2/1024}')"
done
gw=$(cut -d' ' -f1 "$WORK/go" | median); gm=$(cut -d' ' -f2 "$WORK/go" | median)
aw=$(cut -d' ' -f1 "$WORK/av" | median); am=$(cut -d' ' -f2 "$WORK/av" | median)
printf '%-6s %12s %12.1f   %12s %12.1f\n' median "$gw" "$(echo "$gm" | awk '{print $1/1024}')" "$aw" "$(echo "$am" | awk '{print $1/1024}')"
awk -v aw="$aw" -v gw="$gw" -v am="$am" -v gm="$gm" 'BEGIN {
    rss = gm > 0 ? sprintf("%.2f", am / gm) : "unknown (no GNU time)"
    printf "aviary / go: wall %.2f, peak RSS %s  (at most 1.0 each is the target)\n", aw / gw, rss }'
