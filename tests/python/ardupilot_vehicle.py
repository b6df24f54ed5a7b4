"""An ArduPilot-style vehicle (ArduSub's mission and command handling) written with pymavlink
2.4.50, for end-to-end tests of Shoal's `mavlink` link: the behaviours MAVSDK cannot play.

Listens on `udpin:127.0.0.1:PORT` (the link connects with `udpout:`) as system 1 component 1:

- HEARTBEAT (1 Hz): MAV_TYPE_SUBMARINE, MAV_AUTOPILOT_ARDUPILOTMEGA, custom_mode the ArduSub mode
  number (MANUAL 19 until a mission starts, AUTO 3, POSHOLD 16);
- the mission microservice for missions and fences (MISSION_REQUEST_INT per item, MISSION_ACK).
  As ArduPilot does, item 0 of a mission is its home, so it is overwritten with where the vehicle
  is, and the mission runs from item 1. A fence upload is accepted and printed, or answered
  MAV_MISSION_UNSUPPORTED with `--no-fence`;
- MAV_CMD_MISSION_START: AUTO, drives the mission from item 1 (ACCEPTED; FAILED without one);
- MAV_CMD_DO_PAUSE_CONTINUE per `--pause`: `accept` pauses (param1 0) and resumes (1), `refuse`
  answers MAV_RESULT_FAILED with "Failed to pause" as ArduCopter's handle_command_pause_continue
  does when it cannot, `ignore` answers nothing;
- MAV_CMD_DO_SET_MODE (param1 with MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, param2 the ArduSub mode) per
  `--mode`: `accept` switches (POSHOLD 16 and any other mode but AUTO stop the vehicle where it is,
  AUTO 3 resumes), `refuse` answers MAV_RESULT_FAILED as a failed set_mode does;
- any other command: MAV_RESULT_UNSUPPORTED;
- streams GLOBAL_POSITION_INT (10 Hz) and MISSION_CURRENT (1 Hz: the item under way, total = the
  last item's number as the MAVLink spec has it for an autopilot that keeps home in the mission,
  mission_state), and sends MISSION_ITEM_REACHED as each item completes (ArduSub's
  verify_command_callback does for every item), except the last one with `--drop-last-reached`.

Real ArduSub (ArduSub/commands_logic.cpp, Sub::start_command) runs only navigation items at or
below the surface in MAV_FRAME_GLOBAL_RELATIVE_ALT(_INT), home being at the surface: "BAD NAV
AltFrame" otherwise. This vehicle drives AMSL frames all the same and prints a `warning` line per
upload naming the items real ArduSub would refuse; relative altitudes are above the surface (0 m).

The vehicle moves as `vehicle_kinematics` says. JSON lines on stdout, as `mavsdk_vehicle.py`:
`listening`, `mission` (items as received), `home` (what item 0 became), `warning`, `fence`,
`started` (the legs, with the speed each uses and the item that set it), `command` (every
COMMAND_LONG with the result sent, null for none), `holding`, `resumed`, `item_reached` (with
`sent`), `position` (1 Hz), `arrived`, then `stopped` or `timeout`. Exits 0 on SIGTERM or when
stdin closes (unless `--ignore-stdin`), 2 after `--timeout` seconds.

    python ardupilot_vehicle.py PORT [--pause accept|refuse|ignore] [--mode accept|refuse]
        [--drop-last-reached] [--no-fence] [--home LAT,LON,ALT] [--default-speed M_S]
        [--timeout S] [--ignore-stdin]
"""

import argparse
import os
import signal
import sys
import threading
import time

# MAVLink 2 from the first message: the mission messages carry `mission_type` only in v2.
os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil  # noqa: E402  (after MAVLINK20 is set)

import vehicle_kinematics as vk  # noqa: E402
from vehicle_kinematics import emit  # noqa: E402

m = mavutil.mavlink
MANUAL, AUTO, POSHOLD = 19, 3, 16  # ArduSub mode numbers (ArduSub/mode.h)
SURFACE_ALT = 0.0  # ArduSub's home altitude: the surface, so depths are negative
NO_MISSION, NOT_STARTED, ACTIVE, PAUSED, COMPLETE = 1, 2, 3, 4, 5  # MISSION_STATE


class Upload:
    """An incoming transfer of one mission type."""

    def __init__(self, kind, count, peer):
        self.kind, self.count, self.peer, self.items = kind, count, peer, []


class Vehicle:
    def __init__(self, args, conn):
        self.args, self.conn, self.mav = args, conn, conn.mav
        self.runner = vk.Runner(args.home)
        self.items, self.mode, self.upload, self.arrived = [], MANUAL, None, False
        self.peer = (255, 190)

    # -- the mission microservice ---------------------------------------------------------------

    def on_count(self, msg):
        kind = getattr(msg, "mission_type", 0)
        if kind == m.MAV_MISSION_TYPE_FENCE and self.args.no_fence:
            self.mav.mission_ack_send(*self.peer, m.MAV_MISSION_UNSUPPORTED, kind)
            emit({"event": "fence_refused", "count": msg.count})
            return
        self.upload = Upload(kind, msg.count, self.peer)
        self.request_next()

    def request_next(self):
        up = self.upload
        if len(up.items) < up.count:
            self.mav.mission_request_int_send(*up.peer, len(up.items), up.kind)
            return
        self.mav.mission_ack_send(*up.peer, m.MAV_MISSION_ACCEPTED, up.kind)
        self.upload = None
        if up.kind == m.MAV_MISSION_TYPE_FENCE:
            emit({"event": "fence", "items": up.items})
        elif up.kind == m.MAV_MISSION_TYPE_MISSION:
            self.take_mission(up.items)
        else:
            emit({"event": "upload", "mission_type": up.kind, "items": up.items})

    def on_item(self, msg, scale):
        up = self.upload
        if up is None or getattr(msg, "mission_type", 0) != up.kind:
            return
        if msg.seq == len(up.items):
            keys = ("seq", "frame", "command", "current", "autocontinue")
            row = {k: getattr(msg, k) for k in keys}
            row.update({f"param{i}": getattr(msg, f"param{i}") for i in range(1, 5)})
            # MISSION_ITEM (float degrees) arrives from older ground stations: as MISSION_ITEM_INT.
            row.update(x=round(msg.x * scale), y=round(msg.y * scale), z=msg.z)
            up.items.append(row)
        self.request_next()  # the next one, or this one again if it came out of order

    def take_mission(self, items):
        emit({"event": "mission", "items": items})
        self.runner.stop()
        self.items, self.arrived = [dict(i) for i in items], False
        if not self.items:
            return
        lat, lon, alt = self.runner.here
        home = {"seq": 0, "frame": m.MAV_FRAME_GLOBAL, "command": m.MAV_CMD_NAV_WAYPOINT}
        home.update(current=0, autocontinue=1, param1=0.0, param2=0.0, param3=0.0, param4=0.0)
        home.update(x=round(lat * 1e7), y=round(lon * 1e7), z=alt)
        emit({"event": "home", "replaced": self.items[0], "home": home})
        self.items[0] = home
        absolute = [
            i["seq"] for i in self.items[1:]
            if i["command"] == m.MAV_CMD_NAV_WAYPOINT and i["frame"] not in vk.RELATIVE_FRAMES
        ]
        if absolute:
            emit({"event": "warning", "seqs": absolute, "what": "real ArduSub refuses navigation "
                  "items outside MAV_FRAME_GLOBAL_RELATIVE_ALT(_INT): BAD NAV AltFrame"})

    # -- commands -------------------------------------------------------------------------------

    def on_command(self, msg):
        p = [msg.param1, msg.param2, msg.param3, msg.param4, msg.param5, msg.param6, msg.param7]
        result = self.decide(msg.command, p)
        record = {"event": "command", "command": msg.command, "params": p}
        record.update(confirmation=msg.confirmation, result=result)
        emit(record)
        if result is not None:
            self.mav.command_ack_send(msg.command, result, 255, 0, *self.peer)

    def decide(self, command, p):
        """The COMMAND_ACK result for `command`, None for no answer."""
        if command == m.MAV_CMD_MISSION_START:
            if len(self.items) < 2:
                return m.MAV_RESULT_FAILED
            self.mode, self.arrived = AUTO, False
            track = self.runner.start(self.items, self.args.default_speed, SURFACE_ALT, first=1)
            emit({"event": "started", "first": 1, "legs": [leg.report() for leg in track.legs]})
            return m.MAV_RESULT_ACCEPTED
        if command == m.MAV_CMD_DO_PAUSE_CONTINUE:
            if self.args.pause == "ignore":
                return None
            if self.args.pause == "refuse":
                self.mav.statustext_send(m.MAV_SEVERITY_INFO, b"Failed to pause")
                return m.MAV_RESULT_FAILED
            self.set_holding(int(p[0]) == 0, "DO_PAUSE_CONTINUE")
            return m.MAV_RESULT_ACCEPTED
        if command == m.MAV_CMD_DO_SET_MODE:
            if self.args.mode == "refuse" or not int(p[0]) & m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
                return m.MAV_RESULT_FAILED
            self.mode = int(p[1])
            self.set_holding(self.mode != AUTO, "DO_SET_MODE")
            return m.MAV_RESULT_ACCEPTED
        return m.MAV_RESULT_UNSUPPORTED

    def set_holding(self, hold, by):
        if hold != self.runner.holding:
            self.runner.holding = hold
            emit({"event": "holding" if hold else "resumed", "by": by, **self.runner.report()})

    # -- motion and streams ---------------------------------------------------------------------

    def step(self, dt):
        self.runner.advance(dt)
        last = len(self.items) - 1
        for seq in self.runner.newly_completed():
            sent = not (self.args.drop_last_reached and seq == last)
            if sent:
                self.mav.mission_item_reached_send(seq)
            emit({"event": "item_reached", "seq": seq, "sent": sent})
        if self.runner.finished and not self.arrived:
            self.arrived = True
            emit({"event": "arrived", **self.runner.report()})

    def send_position(self, boot):
        lat, lon, alt = self.runner.here
        east, north, up = self.runner.velocity()
        cm = lambda v: int(round(v * 100))  # noqa: E731
        self.mav.global_position_int_send(
            int((time.monotonic() - boot) * 1000), round(lat * 1e7), round(lon * 1e7),
            round(alt * 1000), round((alt - SURFACE_ALT) * 1000), cm(north), cm(east), cm(-up),
            int(round(self.runner.heading_deg * 100)) % 36000,
        )

    def send_status(self):
        base = m.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | m.MAV_MODE_FLAG_SAFETY_ARMED
        if self.mode == AUTO:
            base |= m.MAV_MODE_FLAG_AUTO_ENABLED | m.MAV_MODE_FLAG_GUIDED_ENABLED
        self.mav.heartbeat_send(
            m.MAV_TYPE_SUBMARINE, m.MAV_AUTOPILOT_ARDUPILOTMEGA, base, self.mode, m.MAV_STATE_ACTIVE
        )
        track, runner = self.runner.track, self.runner
        if not self.items:
            self.mav.mission_current_send(0, 65535, NO_MISSION)
            return
        if track is None:
            seq, state = 1, NOT_STARTED
        elif runner.finished:
            seq, state = track.legs[-1].seq if track.legs else 1, COMPLETE
        else:
            leg = track.leg_at(runner.clock)
            seq, state = (leg.seq if leg else 1), (PAUSED if runner.holding else ACTIVE)
        self.mav.mission_current_send(seq, len(self.items) - 1, state)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("port", type=int)
    ap.add_argument("--pause", choices=["accept", "refuse", "ignore"], default="accept")
    ap.add_argument("--mode", choices=["accept", "refuse"], default="accept")
    ap.add_argument("--drop-last-reached", action="store_true")
    ap.add_argument("--no-fence", action="store_true")
    ap.add_argument("--home", type=vk.parse_home, default=(43.1, 5.9, 0.0), help="LAT,LON,ALT")
    ap.add_argument("--default-speed", type=float, default=1.0, help="m/s, until DO_CHANGE_SPEED")
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--ignore-stdin", action="store_true")
    args = ap.parse_args()

    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    if not args.ignore_stdin:
        threading.Thread(target=lambda: (sys.stdin.read(), stop.set()), daemon=True).start()
    conn = mavutil.mavlink_connection(
        f"udpin:127.0.0.1:{args.port}", source_system=1, source_component=1, dialect="common"
    )
    vehicle = Vehicle(args, conn)
    listening = {"event": "listening", "port": args.port, "autopilot": "ardupilotmega"}
    listening.update(pause=args.pause, mode=args.mode, drop_last_reached=args.drop_last_reached)
    emit({**listening, "fence": not args.no_fence})

    began = last = last_position = last_status = last_report = time.monotonic()
    handlers = {
        "MISSION_COUNT": vehicle.on_count,
        "MISSION_ITEM_INT": lambda msg: vehicle.on_item(msg, 1),
        "MISSION_ITEM": lambda msg: vehicle.on_item(msg, 1e7),
        "COMMAND_LONG": vehicle.on_command,
    }
    while not stop.is_set():
        msg = conn.recv_match(blocking=True, timeout=0.02)
        while msg is not None:
            if msg.get_type() != "BAD_DATA":
                vehicle.peer = (msg.get_srcSystem(), msg.get_srcComponent())
                handlers.get(msg.get_type(), lambda _: None)(msg)
            msg = conn.recv_match(blocking=False)
        now = time.monotonic()
        vehicle.step(now - last)
        last = now
        if now - last_position >= 0.1:
            last_position = now
            vehicle.send_position(began)
        if now - last_status >= 1.0:
            last_status = now
            vehicle.send_status()
        if now - last_report >= 1.0:
            last_report = now
            emit({"event": "position", **vehicle.runner.report()})
        if now - began > args.timeout:
            emit({"event": "timeout"})
            return 2
    emit({"event": "stopped"})
    return 0


if __name__ == "__main__":
    sys.exit(main())
