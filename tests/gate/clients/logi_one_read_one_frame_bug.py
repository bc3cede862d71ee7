#!/usr/bin/env python3
# DELIBERATELY BROKEN LOGI client, for hil's gate tests.
#
# The bug: it takes every recv() from the socket as exactly one frame. TCP
# is a byte stream, so a frame cut into pieces (fragmentation) never
# passes the checksum, and several frames that arrive in one read (sticky
# packets) are checked as one and dropped too. Its feedback goes missing,
# its commands time out and are sent again, and the stale warning comes up
# while the car is talking all along.
#
# Everything else is logi_good.py: on a link that delivers one frame per
# read it behaves correctly, so the scenarios that fragment or coalesce the
# car's frames are what reject it.
#
# Usage: logi_one_read_one_frame_bug.py HOST PORT

import logi_good


class OneReadIsOneFrame:
    def feed(self, data):
        return [data.strip()]


class OneReadOneFrameClient(logi_good.LogiClient):
    def make_frame_reader(self):
        return OneReadIsOneFrame()


if __name__ == "__main__":
    logi_good.run(OneReadOneFrameClient)
