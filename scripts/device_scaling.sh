#!/usr/bin/env bash
# Thread scaling and 10M points on a many-core machine (issue 27), in one
# prepared run with a time budget: the device machine lends 15 minutes a
# session, so each step gets a deadline and writes its rows as it goes.
#
#   scripts/device_scaling.sh DIR OUT [BUDGET_S]
#
# DIR holds `aniso-alpha` (a release build), optionally
# `aniso-alpha-base` (an earlier build, timed beside it on the same
# machine), `cgal_shapes` (scripts/peers/cgal_shapes.cpp) and `ahn.ply`
# (the corpus' AHN train tile, scripts/corpus/); OUT gets `all.md` (the
# machine's description, then every table) and one JSON-lines file per
# step (at most 8 files come back from the device machine). The steps, most
# important first (a step that would start past the budget is skipped):
#   1. 64 copies (2.79M points, the region run): 16, 1, 8, 4, 2 threads;
#   2. the same on 16 threads with `aniso-alpha-base`, if there is one;
#   3. 256 copies (11.1M points, the region run): 16 threads;
#   4. 64 copies as one whole run (--regions off): 16 threads, then the
#      same with glibc's default malloc arenas (MALLOC_ARENA_MAX=128);
#   5. 16 copies (697k, one whole run): 1 and 16 threads, CGAL RANSAC;
#   6. 64 copies as one whole run: 1 thread.
set -u
DIR=$1
OUT=$2
BUDGET=${3:-500}
HERE=$(cd "$(dirname "$0")" && pwd)
PRESET="--epsilon 0.15 --cluster-epsilon 0.487987 --min-points 100"
export PYTHONUNBUFFERED=1
{ nproc; grep -m1 "model name" /proc/cpuinfo; free -g | head -2; } > "$OUT/all.md" 2>&1
cat "$OUT/all.md"

# step NAME SECONDS BINARY ARGS...: bench_scaling.py with a deadline of
# SECONDS, or what is left of the budget if less.
step() {
    local name=$1 want=$2 bin=$3
    shift 3
    local left=$((BUDGET - SECONDS))
    local d=$((want < left ? want : left))
    if [ "$d" -le 5 ] || [ ! -x "$bin" ]; then
        echo "## $name: skipped" | tee -a "$OUT/all.md"
        return
    fi
    echo "## $name ($(basename "$bin"), deadline ${d} s)" | tee -a "$OUT/all.md"
    python3 "$HERE/bench_scaling.py" --bin "$bin" --scan "$DIR/ahn.ply" --spacing 1 \
        --deadline "$d" --json "$OUT/$name.json" "$@" | tee -a "$OUT/all.md"
}

NEW=$DIR/aniso-alpha
step threads_2m8 150 "$NEW" --copies 64 --threads 16,1,8,4,2
step base_2m8 25 "$DIR/aniso-alpha-base" --copies 64 --threads 16
step regions_11m 45 "$NEW" --copies 256 --threads 16
step whole_2m8 50 "$NEW" --copies 64 --regions off --threads 16
# The same with glibc's default arena count (the program sets one arena
# unless the environment says otherwise: crates/aniso-alpha-cli/src/memory.rs).
MALLOC_ARENA_MAX=128 step arenas_2m8 50 "$NEW" --copies 64 --regions off --threads 16
step whole_697k 40 "$NEW" --copies 16 --threads 1,16 --peer "$DIR/cgal_shapes" --peer-args "$PRESET"
step whole_2m8_1 600 "$NEW" --copies 64 --regions off --threads 1
echo "done in ${SECONDS} s"
