# Prints the bed ids of a study (or of every study with study=all), one per
# seed: <config>-s<seed> (<same_as>-s<seed> for a same_as row), seeds
# 1..min(seeds, repeats) (repeats empty: all).
# Used by pipelines/paper.mk: awk -F, -v study=S -v repeats=R -f ids.awk TABLE
NR > 1 && $1 != "" && $1 !~ /^#/ && (study == "all" || $2 == study) {
    n = $5 + 0
    if (repeats != "" && repeats + 0 < n) n = repeats + 0
    # A same_as row (column 16) is another row's beds: its ids are that row's.
    name = ($16 != "") ? $16 : $1
    for (s = 1; s <= n; s++) printf "%s-s%d\n", name, s
}
