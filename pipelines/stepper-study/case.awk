# Writes the pack case file (TOML) of one bed of the stepper study's own
# table (pipelines/stepper-study/beds.csv, beds that are not in the paper's
# table): awk -F, -v id=<config>-s<seed> -f case.awk TABLE. The voidprof
# window rides along as a comment that stepper-study.mk reads back, as in the
# paper's case files. stepper-study.mk adds the stepper and its step.
NR > 1 {
    want = id
    sub(/-s[0-9]+$/, "", want)
    seed = substr(id, length(want) + 3)
    if ($1 != want) next
    found = 1
    printf "# packbed stepper study, bed %s, made by pipelines/stepper-study.mk from its bed table\n", id
    printf "# voidprof-window: %s,%s\n", $5, $6
    printf "pellet = \"../%s.pellet\"\n", $2
    printf "tube-diameter = %s\ncount = %s\nseed = %s\nscheme = \"%s\"\n", $3, $4, seed, $7
    if ($8 != "") printf "max-time = %s\n", $8
}
END { if (!found) { print "case.awk: no row for bed " id > "/dev/stderr"; exit 2 } }
