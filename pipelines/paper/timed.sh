#!/bin/sh
# timed.sh [-a] FILE CMD ARGS...: runs CMD, then writes "<seconds> <exit code>"
# to FILE (atomically: FILE.tmp, then mv) and exits with CMD's code. The
# report sums these files into the study's compute time. With -a the seconds
# already in FILE are added (the legs of a run continued by `pack --resume`).
add=0
if [ "$1" = "-a" ]; then add=1; shift; fi
out=$1; shift
before=0
if [ $add = 1 ] && [ -f "$out" ]; then before=$(awk '{ print $1 + 0 }' "$out"); fi
# An interrupt (make killed, Ctrl-C) reaches CMD too; wait for it to stop cleanly
# and still record its time, so that a run continued later counts every leg.
trap : INT TERM HUP
start=$(date +%s.%N)
"$@"; status=$?
end=$(date +%s.%N)
echo "$start $end $status $before" | awk '{ printf "%.3f %d\n", $2 - $1 + $4, $3 }' > "$out.tmp" && mv "$out.tmp" "$out"
exit $status
