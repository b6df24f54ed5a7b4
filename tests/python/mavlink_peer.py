"""An independent MAVLink vehicle for Shoal's `mavlink` link, written with pymavlink (2.4.50).

Plays the vehicle side of the mission microservice and of a few commands, so the Rust link is
checked against an implementation it shares no code with:

- listens on `udpin:127.0.0.1:PORT` (the link connects with `udpout:`), as system 1 component 1;
- receives a mission upload: a MISSION_REQUEST_INT per item, then MISSION_ACK accepted;
- prints every received item as one JSON line on stdout (`{"event": "item", ...}`) and every
  COMMAND_LONG as `{"event": "command", ...}`;
- after the upload, streams GLOBAL_POSITION_INT at the last waypoint (still, heading east),
  MISSION_ITEM_REACHED of the last seq and a HEARTBEAT;
- answers every COMMAND_LONG with COMMAND_ACK accepted, and exits 0 after the first
  MAV_CMD_DO_PAUSE_CONTINUE (the link's stop), or exits 2 after `--timeout` seconds.

    python mavlink_peer.py PORT [--timeout 20]
"""

import argparse
import json
import os
import sys
import time

# MAVLink 2 from the first message: the mission messages carry `mission_type` only in v2.
os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil  # noqa: E402  (after MAVLINK20 is set)


def emit(record):
    print(json.dumps(record), flush=True)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("port", type=int)
    ap.add_argument("--timeout", type=float, default=20.0)
    a = ap.parse_args()

    conn = mavutil.mavlink_connection(
        f"udpin:127.0.0.1:{a.port}", source_system=1, source_component=1, dialect="common"
    )
    mav = conn.mav
    m = mavutil.mavlink
    emit({"event": "listening", "port": a.port})

    deadline = time.monotonic() + a.timeout
    count, expected, items = 0, 0, {}
    peer = (255, 190)
    accepted = False
    last_stream = 0.0
    boot = time.monotonic()

    while time.monotonic() < deadline:
        msg = conn.recv_match(blocking=True, timeout=0.05)
        if msg is not None and msg.get_type() != "BAD_DATA":
            kind = msg.get_type()
            peer = (msg.get_srcSystem(), msg.get_srcComponent())
            if kind == "MISSION_COUNT":
                count, expected, items, accepted = msg.count, 0, {}, False
                mav.mission_request_int_send(peer[0], peer[1], 0)
            elif kind == "MISSION_ITEM_INT":
                if msg.seq == expected and expected < count:
                    items[msg.seq] = msg
                    emit(
                        {
                            "event": "item",
                            "seq": msg.seq,
                            "command": msg.command,
                            "frame": msg.frame,
                            "current": msg.current,
                            "autocontinue": msg.autocontinue,
                            "param1": msg.param1,
                            "param2": msg.param2,
                            "x": msg.x,
                            "y": msg.y,
                            "z": msg.z,
                        }
                    )
                    expected += 1
                if expected < count:
                    mav.mission_request_int_send(peer[0], peer[1], expected)
                else:
                    mav.mission_ack_send(peer[0], peer[1], m.MAV_MISSION_ACCEPTED)
                    accepted = True
            elif kind == "COMMAND_LONG":
                emit({"event": "command", "command": msg.command, "param1": msg.param1})
                mav.command_ack_send(
                    msg.command, m.MAV_RESULT_ACCEPTED, 0, 0, peer[0], peer[1]
                )
                if msg.command == m.MAV_CMD_DO_PAUSE_CONTINUE:
                    emit({"event": "stopped"})
                    return 0
        now = time.monotonic()
        if accepted and now - last_stream >= 0.1:
            last_stream = now
            wps = [i for i in items.values() if i.command == m.MAV_CMD_NAV_WAYPOINT]
            if wps:
                last = wps[-1]
                mav.global_position_int_send(
                    int((now - boot) * 1000), last.x, last.y, int(round(last.z * 1000)),
                    0, 0, 0, 0, 9000,
                )
            mav.mission_item_reached_send(count - 1)
            mav.heartbeat_send(
                m.MAV_TYPE_SUBMARINE, m.MAV_AUTOPILOT_GENERIC, 0, 0, m.MAV_STATE_ACTIVE
            )
    emit({"event": "timeout"})
    return 2


if __name__ == "__main__":
    sys.exit(main())
