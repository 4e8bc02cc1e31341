#!/bin/sh
# benchmarks-md.sh DIR [FILE]: writes FILE (default BENCHMARKS.md) at the end of `make bench`
# from the figures it kept in DIR: pack_beds.txt (the engine's pours), voidprof.txt,
# export.txt (bedexport's stages), steppers.txt, peers.txt and scaling.txt (pipelines/bench-steppers.sh),
# threads.txt (pipelines/bench-threads.sh) and started
# (the run's start, UTC); a missing one is named as not run. Adds the machine (CPU model,
# cores, OS, load averages at the end), the build (git commit, rustc, cargo profile) and the PELLET_BENCH_* and STEPPERS
# settings in the environment. Written to a temporary file beside FILE, then renamed over it.
set -eu
dir=$1
file=${2:-BENCHMARKS.md}
tmp=$(mktemp "$(dirname "$file")/.benchmarks.XXXXXX")
trap 'rm -f "$tmp"' EXIT INT TERM

cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -n 1)
os=$(sed -n 's/^PRETTY_NAME="\{0,1\}\([^"]*\)"\{0,1\}$/\1/p' /etc/os-release 2>/dev/null || true)
commit=$(git rev-parse HEAD 2>/dev/null || echo unknown)
if [ "$commit" != unknown ] && ! git diff --quiet HEAD 2>/dev/null; then
    commit="$commit, with uncommitted changes"
fi
release=$(sed -n '/^\[profile\.release\]/,/^\[/{/^\[/d;/^[[:space:]]*$/d;/^#/d;p;}' Cargo.toml 2>/dev/null | paste -sd ';' - | sed 's/;/; /g')
settings=$(env | grep -E '^(PELLET_BENCH_[A-Z_]*|STEPPERS|THREADS|REPEATS)=' | sort | paste -sd ' ' - || true)
started=$(cat "$dir/started" 2>/dev/null || echo unknown)
load=$(cut -d ' ' -f 1-3 /proc/loadavg 2>/dev/null || echo unknown)

section() {  # title, file in DIR, note under the figures
    printf '\n## %s\n\n' "$1"
    if [ -s "$dir/$2" ]; then
        printf '```text\n'
        cat "$dir/$2"
        printf '```\n'
        [ -z "$3" ] || printf '\n%s\n' "$3"
    else
        printf 'Not run (no %s).\n' "$dir/$2"
    fi
}

{
    printf '# Benchmarks\n\n'
    printf 'Speed figures of packbed on one machine, not tests: written by `make bench`\n'
    printf '(pipelines/benchmarks-md.sh) at the end of its run, replaced by the next one. What the\n'
    printf 'benchmarks measure and earlier figures: [docs/engine.md](docs/engine.md#benchmarks).\n'
    printf '\n## Machine and build\n\n| | |\n|---|---|\n'
    printf '| CPU | %s |\n' "${cpu:-unknown}"
    printf '| cores | %s online (nproc: %s) |\n' "$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo ?)" "$(nproc 2>/dev/null || echo ?)"
    printf '| OS | %s; %s |\n' "${os:-unknown}" "$(uname -srm)"
    printf '| commit | %s |\n' "$commit"
    printf '| rustc | %s |\n' "$(rustc --version 2>/dev/null || echo unknown)"
    printf '| profile | release (`cargo bench`: bench, which inherits it); [profile.release]: %s |\n' "${release:-none, cargo defaults (opt-level 3)}"
    printf '| settings (environment) | %s |\n' "${settings:-none, the defaults}"
    printf '| run | started %s, finished %s |\n' "$started" "$(date -u '+%Y-%m-%d %H:%M UTC')"
    printf '| load at the end | %s (1-, 5- and 15-minute load averages: above the number of cores, other work shared the machine, which the peer ratios, measured side by side, survive and the threads figures do not) |\n' "$load"
    section 'The engine'\''s pours (`cargo bench -p pellet_sim --bench pack_beds`)' pack_beds.txt \
        'Per case: tube D (mm), wall and simulated time (s), substeps, contacts, collisions, resting contacts and solver iterations per substep, residuals, unconverged islands, deepest penetration (fraction of 10 mm), kinetic energy at the end (J), top centre (m), wall s per pellet per simulated s, µs per pellet per substep, and the share (%) of the narrow, collision, resting and projection phases (crates/pellet_sim/benches/pack_beds.rs).'
    section 'voidprof on 600 spheres (`cargo run --release -p pellet_analysis --example bench_voidprof`)' voidprof.txt ''
    section 'bedexport'\''s stages on 600 spheres (`cargo run --release -p pellet_export --example bench_export`)' export.txt ''
    section 'The steppers and the peer engines (`pipelines/bench-steppers.sh`)' steppers.txt \
        'cpu_s: user + system CPU s of `pack`; settle_s: simulated s to settle; ratio: cpu_s over the peer'\''s (yardstick line; ../shared/peers/run.sh) on the same bed; pts/pair, warm_% and conv_%: the velocity stepper'\''s contact solve over the last 0.1 s (contact points a pair, % of loaded contacts warm started, % of steps converged); pen_%: the engine'\''s deepest penetration in the bed as written (% of dpv, pack'\''s "% at the end"); olap_%: the deepest pellet-pellet overlap of the settled bed on the exact shapes (% of dpv, `voidprof --structure`, independent of the engine).'
    section 'The velocity-level stepper and rapier (`STEPPERS=velocity pipelines/bench-steppers.sh BIN "ring256 cyl620"`)' peers.txt \
        'The same columns; the yardsticks are rapier 0.36 pouring the same beds (../shared/peers/run.sh rapier-256-rings, rapier-620).'
    section 'How the velocity-level stepper scales (`STEPPERS=velocity pipelines/bench-steppers.sh BIN "sph690 sph5000 cyl620 cyl2000"`)' scaling.txt \
        'The same columns; ms/N/s, the CPU per pellet per simulated second, of the 5000-sphere and 2000-cylinder beds (the 690-sphere and 620-cylinder beds scaled at their height-to-diameter ratio) against the smaller beds of the same shape shows how the cost grows with the bed.'
    section 'Threads (`pipelines/bench-threads.sh`)' threads.txt \
        'wall_s, cpu_s: medians over the repeats of `pack --threads N`; wall_ratio: wall time over the one-thread run of the same repeat, median (min-max); cpu_ratio: the same for CPU; same_frames: every frame bit for bit the one-thread run'\''s. The serial fraction and what it gives on more cores: [docs/engine.md](docs/engine.md#threads).'
} >"$tmp"
mv "$tmp" "$file"
echo "wrote $file"
