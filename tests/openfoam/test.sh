#!/bin/sh
# test.sh BIN (make test-openfoam): a 20-sphere, a 20-cylinder and a 20-ring bed (10 mm
# pellets, 30 mm tube) made with the binaries in BIN, exported with
# `bedexport --openfoam` (0.5 mm cells; the default caps, bridges and none, sized by dp, with
# the contacts refined), meshed with OpenFOAM (Debian's openfoam package, installed when
# missing): no treatment may warn (a porosity change over 0.01), surfaceCheck must find
# pellets.stl closed and not self-intersecting, and blockMesh,
# surfaceFeatureExtract, snappyHexMesh and checkMesh must give "Mesh OK",
# one region, the patches inlet, outlet, wall and pellets, and a fluid
# volume within 1 % of the tube minus the pellets (caps and bridges on every bed);
# BEDS="spheres rings" runs only those. Then simpleFoam on the
# sphere bed's case, its pressure drop against Ergun's (see flow_bed). Fails (exit 1) when
# OpenFOAM cannot be installed: it never passes by skipping. KEEP=1 keeps the case.
set -u
[ $# -eq 1 ] || { echo "test-openfoam: error: usage: test.sh BIN" >&2; exit 2; }
bin=$(cd "$1" 2>/dev/null && pwd) || { echo "test-openfoam: error: no directory $1 (build first)" >&2; exit 2; }
for t in mkpellet pack settle-check bedexport; do
    [ -x "$bin/$t" ] || { echo "test-openfoam: error: $bin/$t missing (build first)" >&2; exit 2; }
done
start=$(date +%s)
say() { echo "test-openfoam: [$(($(date +%s) - start)) s] $*"; }
fail() { echo "test-openfoam: FAILED: $*" >&2; exit 1; }

# Debian's OpenFOAM v1912 finds its etc files through these.
export FOAM_INST_DIR=/usr/share/openfoam WM_PROJECT_DIR=/usr/share/openfoam
if ! command -v snappyHexMesh >/dev/null; then
    say "installing Debian's openfoam package"
    sudo=; [ "$(id -u)" -eq 0 ] || sudo=sudo
    { $sudo apt-get update && $sudo apt-get install -y --no-install-recommends openfoam; } >/dev/null 2>&1 \
        || fail "OpenFOAM is not installed and 'apt-get install openfoam' failed; install Debian's openfoam package (v1912) and rerun"
    command -v snappyHexMesh >/dev/null || fail "the openfoam package installed no snappyHexMesh on PATH"
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/packbed-openfoam.XXXXXX") || exit 2
[ "${KEEP:-0}" = 1 ] && say "keeping $work" || trap 'rm -rf "$work"' EXIT
cd "$work" || exit 2
# surface_check NAME CASE: surfaceCheck finds CASE's pellets.stl one closed surface
# that does not cross itself (-outputThreshold 0: it writes no part files).
surface_check() {
    (cd "$2" && surfaceCheck -checkSelfIntersection -outputThreshold 0 constant/triSurface/pellets.stl) \
        >"$2/log.surfaceCheck" 2>&1 || { tail -n 30 "$2/log.surfaceCheck" >&2; fail "$1: surfaceCheck failed (log above)"; }
    for ok in "Surface has no illegal triangles." "Surface is closed. All edges connected to two faces." \
        "Surface is not self-intersecting"; do
        grep -qF "$ok" "$2/log.surfaceCheck" || {
            grep -E "illegal|closed|self-intersecting" "$2/log.surfaceCheck" >&2
            fail "$1: pellets.stl: surfaceCheck did not say \"$ok\""
        }
    done
    say "$1: surfaceCheck: pellets.stl closed, not self-intersecting ($(sed -n 's/^Triangles *: \([0-9]*\).*/\1/p' "$2/log.surfaceCheck") triangles)"
}
# mesh_case NAME DIR LOG: blockMesh, surfaceFeatureExtract, snappyHexMesh and checkMesh in DIR
# (written by bedexport with the summary LOG) must give "Mesh OK", one region, the four patches
# and the fluid volume LOG expects within 1 %. Measured (caps, bridges): spheres −0.96 %,
# −0.84 %; cylinders −0.85 %, −0.74 %; rings −0.64 %, −0.57 % (an empty tube −0.10 %:
# most of it is lost at the pellets, in the narrow gaps along their contacts).
mesh_case() {
    expected=$(sed -n 's/^fluid volume: \([^ ]*\) m3.*/\1/p' "$3")
    [ -n "$expected" ] || { cat "$3" >&2; fail "$1: bedexport printed no fluid volume"; }
    cd "$2" || exit 2
    for step in blockMesh surfaceFeatureExtract "snappyHexMesh -overwrite" checkMesh; do
        log=log.${step%% *}
        t0=$(date +%s)
        $step >"$log" 2>&1 || { tail -n 30 "$log" >&2; fail "$1: $step failed (log above)"; }
        say "$1: $step done ($(($(date +%s) - t0)) s)"
    done
    grep -q "Mesh OK" log.checkMesh || { tail -n 40 log.checkMesh >&2; fail "$1: checkMesh did not say Mesh OK"; }
    grep -q "Number of regions: 1 (OK)" log.checkMesh || fail "$1: the fluid is not one connected region"
    for patch in inlet outlet wall pellets; do
        grep -Eq "^ *$patch\$" constant/polyMesh/boundary || fail "$1: patch $patch missing (constant/polyMesh/boundary)"
    done
    meshed=$(sed -n 's/.*Total volume = \([^ ]*\)\..*/\1/p' log.checkMesh | head -n 1)
    [ -n "$meshed" ] || fail "$1: checkMesh printed no total volume"
    awk -v m="$meshed" -v e="$expected" 'BEGIN { d = (m - e) / e; if (d < 0) d = -d; exit !(d <= 0.01) }' \
        || fail "$1: meshed fluid volume $meshed m3 is not within 1 % of $expected m3"
    cells=$(sed -n 's/^ *cells: *\([0-9]*\)/\1/p' log.checkMesh | head -n 1)
    say "$1: passed: Mesh OK, $cells cells, fluid volume $meshed m3 (expected $expected m3)"
    cd "$work" || exit 2
}
# mesh_bed NAME TREATMENTS mkpellet-arguments…: a 20-pellet bed exported with the default caps,
# bridges and none (surfaceCheck on each, the porosity change printed); the treatments in
# TREATMENTS (a comma-separated list of caps and bridges) are meshed.
mesh_bed() {
    name=$1 treatments=$2; shift 2
    mkdir "$name" && cd "$name" || exit 2
    "$bin/mkpellet" "$@" -o p.pellet >/dev/null || fail "$name: mkpellet"
    "$bin/pack" --pellet p.pellet --tube-diameter 30 --count 20 --scheme batch -o b.mcap >pack.log 2>&1 || fail "$name: pack (pack.log)"
    "$bin/settle-check" b.mcap -o b.packing >settle.log 2>&1 || fail "$name: settle-check (settle.log)"
    say "$name: bed made"
    for t in caps bridges none; do
        "$bin/bedexport" b.packing --openfoam case-$t --treatment $t --cell-size 0.5 --inlet 5 --outlet 5 >export-$t.log 2>export-$t.err \
            || { cat export-$t.err >&2; fail "$name: bedexport --openfoam --treatment $t"; }
        if grep -q "warning" export-$t.err; then
            cat export-$t.err >&2
            fail "$name: --treatment $t warns (its default changes the porosity by more than 0.01)"
        fi
        surface_check "$name (--treatment $t)" case-$t
        [ $t = none ] || say "$name: $(grep -E "^$t: " export-$t.log | sed 's/ (.*//')"
        [ $t = none ] || say "$name: $(grep -E "^contact refinement: " export-$t.log)"
    done
    # The default treatment is caps: `case` is the case flow_bed runs.
    mv case-caps case && mv export-caps.log export.log
    cd "$work" || exit 2
    case ",$treatments," in *,caps,*) mesh_case "$name" "$work/$name/case" "$work/$name/export.log" ;; esac
    case ",$treatments," in *,bridges,*) mesh_case "$name (bridges)" "$work/$name/case-bridges" "$work/$name/export-bridges.log" ;; esac
}
# flow_bed NAME: simpleFoam on NAME's meshed case (bedexport's default laminar set-up: water
# at 20 °C, Re_p = u_s dp / nu = 10) must converge, carry the inlet's flow rate to the outlet
# (within 1 %), and give a pressure drop per unit length over the packed section (the planes
# bedBottom at the floor and bedTop one dp below the bed's top, as voidprof's porosity: the
# empty inlet and outlet tube and the loose top layer are left out) within a factor of 3 of
# Ergun's and a factor of 2 of Eisfeld & Schnitzlein's wall-corrected correlation, both at the
# porosity of the packed section as exported. Why these bands: with D/dp = 3 the wall adds
# friction in the viscous regime (Eisfeld & Schnitzlein, Chem. Eng. Sci. 56 (2001) 4321; Di
# Felice & Gibilaro, Chem. Eng. Sci. 59 (2004) 3037), so at Re_p = 10 Eisfeld & Schnitzlein
# predict about twice Ergun's drop; three layers of 20 spheres are far from a homogeneous bed,
# and the mesh (dp/20 at the pellets, caps of dp/100 at the contacts, refined to dp/80) is coarse.
flow_bed() {
    name=$1
    cd "$work/$name/case" || exit 2
    t0=$(date +%s)
    simpleFoam >log.simpleFoam 2>&1 || { tail -n 30 log.simpleFoam >&2; fail "$name: simpleFoam failed (log above)"; }
    seconds=$(($(date +%s) - t0))
    iterations=$(sed -n 's/^SIMPLE solution converged in \([0-9]*\) iterations/\1/p' log.simpleFoam)
    [ -n "$iterations" ] || { tail -n 20 log.simpleFoam >&2; fail "$name: simpleFoam did not converge"; }
    last() { tail -n 1 "postProcessing/$1/0/surfaceFieldValue.dat" | awk '{ print $2 }'; }
    bottom=$(last bedBottom) top=$(last bedTop) inlet=$(last inlet) flow=$(last flowRate)
    packed=$(sed -n 's/^packed section: z 0.000 to \([^ ]*\) mm.*, porosity \([^ ]*\) as exported.*/\1 \2/p' ../export.log)
    fluid=$(sed -n 's/^flow: .*(nu \([^ ]*\) m2\/s, rho \([^ ]*\) kg\/m3), .* on dp \([^ ]*\) mm .*: u_s \([^ ]*\) m\/s.*/\1 \2 \3 \4/p' ../export.log)
    [ -n "$packed" ] && [ -n "$fluid" ] || { cat ../export.log >&2; fail "$name: bedexport printed no packed section or flow"; }
    radius=$(sed -n 's/.*(radius \([^ ]*\) m);/\1/p' README)
    result=$(echo "$bottom $top $inlet $flow $packed $fluid $radius" | awk '{
        pb = $1; pt = $2; pin = $3; q = $4; L = $5 * 1e-3; e = $6; nu = $7; rho = $8; dp = $9 * 1e-3; u = $10; R = $11
        mu = nu * rho
        measured = rho * (pb - pt) / L
        ergun = 150 * mu * u * (1 - e)^2 / (e^3 * dp^2) + 1.75 * rho * u^2 * (1 - e) / (e^3 * dp)
        # Eisfeld & Schnitzlein (2001), spheres: K1 = 154, k1 = 1.15, k2 = 0.87.
        aw = 1 + 2 / (3 * (2 * R / dp) * (1 - e)); bw = (1.15 * (dp / (2 * R))^2 + 0.87)^2
        es = 154 * aw^2 * mu * u * (1 - e)^2 / (e^3 * dp^2) + aw / bw * rho * u^2 * (1 - e) / (e^3 * dp)
        qin = u * 3.14159265358979 * R * R
        printf "%.4g %.4g %.4g %.3f %.3f %.4f %.4g %.4g %.4f", measured, ergun, es, measured / ergun, measured / es, q / qin, rho * pin, rho * (pb - pt), e
    }')
    set -- $result
    cells=$(sed -n 's/^ *cells: *\([0-9]*\)/\1/p' log.checkMesh | head -n 1)
    say "$name: simpleFoam: $cells cells, converged in $iterations iterations, $seconds s"
    say "$name: packed section: porosity $9, dp/L $1 Pa/m measured ($8 Pa; inlet to outlet $7 Pa); Ergun $2 Pa/m, Eisfeld-Schnitzlein $3 Pa/m"
    say "$name: measured / Ergun = $4, measured / Eisfeld-Schnitzlein = $5, outlet / inlet flow rate = $6"
    awk -v r="$6" 'BEGIN { exit !(r > 0.99 && r < 1.01) }' || fail "$name: the outlet carries $6 of the inlet's flow rate (not within 1 %)"
    awk -v r="$4" 'BEGIN { exit !(r > 1 / 3 && r < 3) }' || fail "$name: measured / Ergun = $4 is outside (1/3, 3)"
    awk -v r="$5" 'BEGIN { exit !(r > 0.5 && r < 2) }' || fail "$name: measured / Eisfeld-Schnitzlein = $5 is outside (0.5, 2)"
    say "$name: flow passed"
    cd "$work" || exit 2
}
# BEDS (default: all three) picks the beds, e.g. BEDS=rings.
beds=${BEDS:-spheres cylinders rings}
for bed in $beds; do
    case $bed in
        spheres) mesh_bed spheres caps,bridges sphere --diameter 10 && flow_bed spheres ;;
        cylinders) mesh_bed cylinders caps,bridges cylinder --diameter 10 --height 10 ;;
        rings) mesh_bed rings caps,bridges ring --outer-diameter 10 --inner-diameter 6 --height 10 ;;
        *) echo "test-openfoam: error: unknown bed $bed in BEDS (spheres, cylinders, rings)" >&2; exit 2 ;;
    esac
done
say "passed: $beds"
