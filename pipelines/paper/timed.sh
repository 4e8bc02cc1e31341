#!/bin/sh
# timed.sh FILE CMD ARGS...: runs CMD, then writes "<seconds> <exit code>"
# to FILE (atomically: FILE.tmp, then mv) and exits with CMD's code. The
# report sums these files into the study's compute time.
out=$1; shift
start=$(date +%s.%N)
"$@"; status=$?
end=$(date +%s.%N)
echo "$start $end $status" | awk '{ printf "%.3f %d\n", $2 - $1, $3 }' > "$out.tmp" && mv "$out.tmp" "$out"
exit $status
