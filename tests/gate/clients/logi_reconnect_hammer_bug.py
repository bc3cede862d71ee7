#!/usr/bin/env python3
# DELIBERATELY BROKEN LOGI client, for hil's gate tests.
#
# The bug: after the connection drops, or an attempt fails, it tries again
# every 100 ms, forever, instead of backing off 1 s, 2 s, 3 s and then
# every 3 s as the LOGI car's documentation asks. A car that is rebooting
# or hangs up on every connection is hammered with attempts.
#
# Everything else is logi_good.py: while the link stays up it behaves
# correctly, so the scenarios that drop the connection or refuse new ones
# are what reject it.
#
# Usage: logi_reconnect_hammer_bug.py HOST PORT

import logi_good


class ReconnectHammerClient(logi_good.LogiClient):
    def reconnect_delay(self, failures_in_a_row):
        return 0.1


if __name__ == "__main__":
    logi_good.run(ReconnectHammerClient)
