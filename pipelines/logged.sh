#!/bin/sh
# logged.sh LOG CMD [ARG...]: runs CMD with its stdout and stderr in the file LOG (created, or
# emptied, after a first line `$ CMD ARG...`), so that a pipeline's terminal stays short. When
# CMD fails, its last lines and the log's path go to stderr, and logged.sh exits with CMD's
# exit status. Used by pipelines/default.mk.
log=$1
shift
mkdir -p "$(dirname "$log")" || exit 2
printf '$ %s\n' "$*" >"$log" || exit 2
"$@" >>"$log" 2>&1 && exit 0
status=$?
{
    echo "failed (exit $status): $*"
    tail -n 15 "$log" | sed 's/^/  | /'
    echo "  (its whole output: $log)"
} >&2
exit $status
