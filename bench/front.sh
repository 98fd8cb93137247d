#!/usr/bin/env bash
# The pre-flight analyses at scale (docs/BENCHMARKS.md, "Pre-flight analyses at scale"):
# `aviary bench front` on N statements in one SEQUENTIAL block and on a chain of
# capabilities, each the whole of `aviary check` minus reading and printing.
#
#   bench/front.sh [RUNS]      default 3 runs per size; the median is printed
#
# Builds Aviary in release mode. Each size runs under `timeout` (600 s), so a quadratic
# build still finishes the script. Prints the machine's CPU first.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-3}
cargo build --release -q -p aviary-cli
AVIARY=target/release/aviary
lscpu | grep -E '^(Model name|CPU\(s\)|Thread|CPU max MHz|BogoMIPS)' || true
for n in 20000 40000 80000 1500000; do
    echo "== sequential, $n statements"
    timeout 600 "$AVIARY" bench front --shape sequential --n "$n" --runs "$RUNS" || echo "(stopped after 600 s or failed)"
done
for n in 50000; do
    echo "== chain, $n capabilities"
    timeout 600 "$AVIARY" bench front --shape chain --n "$n" --runs "$RUNS" || echo "(stopped after 600 s or failed)"
done
