#!/usr/bin/env bash
# Regenerates the peer comparison: builds what is needed, runs the six scenes on every engine
# scene by scene, interleaved (for each scene: rapier_fvm, pybullet, MuJoCo, rapier's built-in
# soft bodies, in turn), so that a change of machine load falls on all engines alike; writes
# every JSON line to out/compare/all.jsonl, then BENCHMARKS.md and docs/benchmarks/*.png.
#
#   bash benches/compare/run_all.sh            # everything (~20 min on 2 cores)
#   bash benches/compare/run_all.sh --quick    # smallest case of each scene (~1 min + builds)
#
# Environment: CARGO_TARGET_DIR (the workspace's target directory, default ./target),
# RAPIER_BUILTIN_TARGET_DIR (the standalone rapier_builtin crate's, default its own ./target),
# CARGO_BUILD_JOBS (cargo's), COMPARE_VENV (the Python environment, see setup.sh).
#
# Besides the cases, all.jsonl holds a line {"kind": "run", ...} first (date, CPU model, CPU
# count, load average, git commit, command) and last (total time, load average), and a line
# {"kind": "engine_run", ...} per engine and scene (its wall time and exit status).
# Each engine's progress goes to out/compare/log/<engine>_<scene>.log.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
quick=()
case "${1:-}" in
    --quick) quick=(--quick) ;;
    "") ;;
    *) echo "usage: $0 [--quick]" >&2; exit 2 ;;
esac

out="out/compare"
log="$out/log"
all="$out/all.jsonl"
target="${CARGO_TARGET_DIR:-$root/target}"
builtin_dir="benches/compare/rapier_builtin"
builtin_target="${RAPIER_BUILTIN_TARGET_DIR:-$root/$builtin_dir/target}"
venv="${COMPARE_VENV:-$root/benches/compare/.venv}"
scenes=(cantilever poisson vibration drop box_on_block scaling)
start=$(date +%s)

echo "== building" >&2
bash benches/compare/setup.sh "$venv" >&2
cargo build --release -p rapier_fvm_cases -p compare_report >&2
(cd "$builtin_dir" && CARGO_TARGET_DIR="$builtin_target" cargo build --release) >&2

mkdir -p "$log"
: > "$all"

# One {"kind": "run"} line: the machine and the moment.
run_line() {
    local phase="$1" extra="$2"
    local cpu load commit
    cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//;s/"/\\"/g' || true)
    load=$(cut -d' ' -f1-3 /proc/loadavg)
    commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
    if ! git diff --quiet HEAD 2>/dev/null; then commit="$commit+changes"; fi
    printf '{"kind": "run", "phase": "%s", "date": "%s", "nproc": %s, "cpu_model": "%s", "loadavg": "%s", "git_commit": "%s", "command": "bash benches/compare/run_all.sh%s"%s}\n' \
        "$phase" "$(date -u +%Y-%m-%dT%H:%M:%SZ)" "$(nproc)" "$cpu" "$load" "$commit" \
        "${quick[*]:+ ${quick[*]}}" "$extra" >> "$all"
}

# Runs one engine on one scene; its JSON lines go to all.jsonl, its progress to the log.
run_engine() {
    local engine="$1" scene="$2"
    shift 2
    local t0 status=0 lines
    t0=$(date +%s.%N)
    lines=$(mktemp)
    echo "== $scene: $engine" >&2
    "$@" --scene "$scene" "${quick[@]}" > "$lines" 2> "$log/${engine}_${scene}.log" || status=$?
    cat "$lines" >> "$all"
    rm -f "$lines"
    tail -n 1 "$log/${engine}_${scene}.log" >&2 || true
    printf '{"kind": "engine_run", "engine": "%s", "scene": "%s", "wall_s": %.1f, "exit_status": %d}\n' \
        "$engine" "$scene" "$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')" \
        "$status" >> "$all"
}

run_line start ""
for scene in "${scenes[@]}"; do
    run_engine rapier_fvm "$scene" "$target/release/compare_cases"
    run_engine pybullet "$scene" "$venv/bin/python" benches/compare/pybullet_cases.py
    run_engine mujoco "$scene" "$venv/bin/python" benches/compare/mujoco_cases.py
    run_engine rapier_builtin "$scene" "$builtin_target/release/rapier_builtin_cases"
done
run_line end ", \"total_s\": $(( $(date +%s) - start ))"

echo "== report" >&2
"$target/release/compare_report" --input "$all" --markdown BENCHMARKS.md --plots docs/benchmarks
echo "done in $(( $(date +%s) - start )) s: $all, BENCHMARKS.md, docs/benchmarks/" >&2
