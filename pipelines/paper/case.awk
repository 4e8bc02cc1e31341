# Writes the pack case file (TOML) of one bed: awk -F, -v id=<config>-s<seed>
# -f case.awk TABLE. Empty cells are left out, so pack's
# defaults (the paper's validation values) apply. The voidprof window rides
# along as a comment that paper.mk reads back.
NR > 1 {
    want = id
    sub(/-s[0-9]+$/, "", want)
    seed = substr(id, length(want) + 3)
    if ($1 != want) next
    found = 1
    # No label here: editing a label must not re-run hours of beds.
    printf "# packbed paper study, bed %s (%s), made by pipelines/paper.mk from the bed table\n", id, $2
    printf "# voidprof-window: %s,%s\n", $7, $8
    # Case files sit in $(OUT)/cases, the pellets in $(OUT); pack reads a case file's paths
    # relative to the case file.
    printf "pellet = \"../%s.pellet\"\n", $3
    printf "tube-diameter = %s\nfill-height = %s\nseed = %s\nscheme = \"%s\"\n", $4, $6, seed, $9
    if ($10 != "") printf "cor = %s\n", $10
    if ($11 != "") printf "friction = %s\n", $11
    if ($12 != "") printf "position-jitter = %s\n", $12
    if ($13 != "") printf "angle-jitter = %s\n", $13
    if ($14 != "") printf "max-time = %s\n", $14
    if ($17 != "") printf "drop-height = %s\n", $17
    if ($18 != "") printf "release-height = %s\n", $18
}
END { if (!found) { print "case.awk: no row for bed " id > "/dev/stderr"; exit 2 } }
