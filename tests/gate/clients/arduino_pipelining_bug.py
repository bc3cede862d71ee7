#!/usr/bin/env python3
# DELIBERATELY BROKEN Arduino client, for hil's gate tests.
#
# The bug: it reports each request done as soon as the frame is written,
# without waiting for the board's answer, so the next operator action's
# request goes out while the last one is still on its way (pipelining).
# The board handles one frame at a time and its serial line is slow
# (9,600 baud: a 14-byte request takes 14.6 ms), so a client that pipelines
# gets answers it cannot tell apart from its requests' and reports results
# it never saw.
#
# It is arduino_good.py with that one bug planted (`--bug pipelining`), so a
# scenario that checks the order of requests and answers on the wire is
# what rejects it.
#
# Usage: arduino_pipelining_bug.py PTY

import sys

import arduino_good

if __name__ == "__main__":
    sys.exit(arduino_good.main(["--bug", "pipelining"] + sys.argv[1:]))
