#!/bin/sh
# A client that is slow to start, as a JVM or a big Python program is:
# waits SECONDS, then becomes COMMAND (exec: the same process, with hil's
# stdin, stdout and environment), so a correct client behind it connects
# that much later than hil started it.
#
#   slow_start.sh SECONDS COMMAND [ARGUMENT...]
#   slow_start.sh 2 python3 -u tests/gate/clients/logi_good.py {host} {port}
set -eu

usage="usage: slow_start.sh SECONDS COMMAND [ARGUMENT...]"
if [ "$#" -lt 2 ]; then
  echo "slow_start.sh: expected a delay and a command; $usage" >&2
  exit 2
fi
case "$1" in
  '' | *[!0-9.]* | *.*.* | .)
    echo "slow_start.sh: the delay '$1' is not a number of seconds; $usage" >&2
    exit 2
    ;;
esac
delay=$1
shift
sleep "$delay"
exec "$@"
