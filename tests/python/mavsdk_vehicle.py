"""MAVSDK 4.1 as the vehicle: an autopilot written by others, for end-to-end tests of Shoal's
`mavlink` link.

MAVSDK (https://mavsdk.mavlink.io, the `mavsdk` 4.x package: ctypes over the C++ library) runs as
an autopilot component, system 1 component 1, MAV_TYPE_SUBMARINE, with its server plugins:

- MissionRawServer answers the mission microservice (MISSION_COUNT, MISSION_REQUEST_INT per
  item, MISSION_ACK) for missions, fences and rally points, and sends MISSION_ITEM_REACHED and
  MISSION_CURRENT when this script calls `set_current_item_complete()`;
- TelemetryServer sends our position as GLOBAL_POSITION_INT (10 Hz);
- ActionServer (with `--hold refuse` only) answers MAV_CMD_DO_SET_MODE: it reads the PX4 custom
  modes and refuses Hold (AUTO.LOITER) with MAV_RESULT_TEMPORARILY_REJECTED whatever the
  allowable flight modes say;
- MavlinkDirectServer shows every COMMAND_LONG, and answers those MAVSDK has no handler for:
  MAV_CMD_MISSION_START always; MAV_CMD_DO_PAUSE_CONTINUE with `--hold accept` (ACCEPTED) or
  `--hold refuse` (UNSUPPORTED); MAV_CMD_DO_SET_MODE with `--hold accept` (ACCEPTED for PX4
  AUTO.LOITER and AUTO.MISSION, UNSUPPORTED for other modes). With `--hold ignore` nothing answers
  DO_PAUSE_CONTINUE or DO_SET_MODE: MAVSDK sends no COMMAND_ACK for a command without a handler.

The link reaches it at `udpout:127.0.0.1:PORT`. MAVSDK's connection is `raw://`: this script owns
the UDP socket on 127.0.0.1:PORT, hands MAVSDK each datagram and sends what MAVSDK emits back to
the last sender. So it sees MAVSDK's own bytes: the result of every COMMAND_ACK MAVSDK sends is
printed, and with `--autopilot px4` the HEARTBEAT's autopilot field becomes MAV_AUTOPILOT_PX4
(the C API of 4.1 cannot set it: MAVSDK announces MAV_AUTOPILOT_GENERIC).

The vehicle moves as `vehicle_kinematics` says: after MAV_CMD_MISSION_START it drives the mission
in real time from where it is, completes each item through MissionRawServer, stops while holding,
and a new upload replaces the mission (it waits where it is for the next MISSION_START).

Prints one JSON object per line on stdout (MAVSDK's own log goes to stderr): `listening`,
`mission` (every item received), `fence`, `started` (with the legs), `command` (every
COMMAND_LONG, with the COMMAND_ACK result MAVSDK or this script sent, null when none went out),
`flight_mode_change` (ActionServer's verdict), `holding`, `resumed`, `item_reached` and
`mission_current` (as sent on the wire), `position` (1 Hz), `arrived`, then `stopped` or `timeout`.
Exits 0 on SIGTERM or when stdin closes (unless `--ignore-stdin`), 2 after `--timeout` seconds.

    python mavsdk_vehicle.py PORT [--hold ignore|accept|refuse] [--autopilot generic|px4]
        [--home LAT,LON,ALT] [--default-speed M_S] [--timeout S] [--ignore-stdin]
"""

import argparse
import ctypes
import json
import queue
import select
import signal
import socket
import sys
import threading
import time

from mavsdk import ComponentType, Configuration, Mavsdk, log_subscribe
from mavsdk.cmavsdk_loader import _cmavsdk_lib
from mavsdk.plugins.action_server import ActionServer, ActionServerResult, AllowableFlightModes
from mavsdk.plugins.action_server import FlightMode
from mavsdk.plugins.mavlink_direct_server import MavlinkDirectServer, MavlinkMessage
from mavsdk.plugins.mission_raw_server import MissionRawServer, MissionRawServerResult
from mavsdk.plugins.telemetry_server import Heading, Position, TelemetryServer, VelocityNed

import vehicle_kinematics as vk
from vehicle_kinematics import emit

MAV_TYPE_SUBMARINE = 12
MAV_AUTOPILOT_PX4 = 12
MISSION_START, DO_PAUSE_CONTINUE, DO_SET_MODE = 300, 193, 176
ACCEPTED, DENIED, UNSUPPORTED = 0, 2, 3
PX4_AUTO, PX4_LOITER, PX4_MISSION = 4, 3, 4  # PX4 custom main mode and sub modes
# MAVLink 2 ids and CRC_EXTRA of the messages read from MAVSDK's output.
HEARTBEAT, MISSION_CURRENT, MISSION_ITEM_REACHED, COMMAND_ACK = 0, 42, 46, 77
HEARTBEAT_CRC_EXTRA = 50
ACK_WAIT_S = 0.6  # how long a command waits for its COMMAND_ACK before it is printed without


def x25(data, crc=0xFFFF):
    """MAVLink's checksum, CRC-16/MCRF4XX (mavlink.io/en/guide/serialization.html#checksum)."""
    for b in data:
        t = (b ^ crc) & 0xFF
        t = (t ^ (t << 4)) & 0xFF
        crc = ((crc >> 8) ^ (t << 8) ^ (t << 3) ^ (t >> 4)) & 0xFFFF
    return crc


def frames(data):
    """(message id, payload padded with zeros, start, end) of each MAVLink 2 frame in `data`."""
    i = 0
    while i + 12 <= len(data) and data[i] == 0xFD:
        n = data[i + 1]
        end = i + 12 + n + (13 if data[i + 2] & 1 else 0)
        msgid = data[i + 7] | data[i + 8] << 8 | data[i + 9] << 16
        yield msgid, bytes(data[i + 10 : i + 10 + n]) + bytes(16), i, end
        i = end


class Wire:
    """The UDP socket MAVSDK's `raw://` connection talks through."""

    def __init__(self, port, autopilot, events):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", port))
        self.peer, self.autopilot, self.events = None, autopilot, events

    def outgoing(self, data):
        """MAVSDK's bytes: noted, the heartbeat's autopilot set if asked, then sent to the peer."""
        data = bytearray(data)
        for msgid, payload, start, end in frames(data):
            if msgid == HEARTBEAT and self.autopilot is not None and not data[start + 2] & 1:
                data[start + 15] = self.autopilot  # payload byte 5: autopilot
                crc = x25(bytes(data[start + 1 : end - 2]) + bytes([HEARTBEAT_CRC_EXTRA]))
                data[end - 2 : end] = crc.to_bytes(2, "little")
            elif msgid == COMMAND_ACK:
                command = payload[0] | payload[1] << 8
                self.events.put(("ack_out", command, payload[2]))
            elif msgid == MISSION_ITEM_REACHED:
                seq = payload[0] | payload[1] << 8
                self.events.put(("wire", {"event": "item_reached", "seq": seq}))
            elif msgid == MISSION_CURRENT:
                seq, total = payload[0] | payload[1] << 8, payload[2] | payload[3] << 8
                self.events.put(("wire", {"event": "mission_current", "seq": seq, "total": total}))
        if self.peer is not None:
            try:
                self.sock.sendto(bytes(data), self.peer)
            except OSError:
                pass  # the link went away: UDP has nobody to tell

    def receive(self, mavsdk, wait_s):
        """Hands MAVSDK every datagram that arrives within `wait_s`."""
        while select.select([self.sock], [], [], wait_s)[0]:
            data, self.peer = self.sock.recvfrom(65536)
            mavsdk.pass_received_raw_bytes(data)
            wait_s = 0.0


def make_mavsdk():
    """MAVSDK configured as an autopilot (system 1, component 1), MAV_TYPE_SUBMARINE."""
    def to_stderr(level, msg, _file, _line):
        print(f"mavsdk {level.name}: {msg}", file=sys.stderr)
        return True  # not MAVSDK's own printing, which goes to stdout

    log_subscribe(to_stderr)
    config = Configuration.create_with_component_type(ComponentType.AUTOPILOT)
    # Exported by libcmavsdk but not wrapped by the 4.1 Python binding.
    _cmavsdk_lib.mavsdk_configuration_set_mav_type.argtypes = [ctypes.c_void_p, ctypes.c_uint8]
    _cmavsdk_lib.mavsdk_configuration_set_mav_type(config._handle, MAV_TYPE_SUBMARINE)
    return Mavsdk(config), config


class Vehicle:
    """MAVSDK's plugins around a `vk.Runner`; callbacks only queue, the main loop decides."""

    def __init__(self, args, mavsdk, wire, events):
        self.args, self.mavsdk, self.wire, self.events = args, mavsdk, wire, events
        self.runner = vk.Runner(args.home)
        self.items, self.mavsdk_seq, self.arrived = [], 0, False
        self.pending, self.acks = [], []  # commands awaiting their ack; acks awaiting a command
        component = mavsdk.server_component()
        self.missions = MissionRawServer(component)
        self.telemetry = TelemetryServer(component)
        self.direct = MavlinkDirectServer(component)
        self.missions.subscribe_incoming_mission(lambda r, plan, _: events.put(("upload", r, plan)))
        self.direct.subscribe_message("COMMAND_LONG", lambda m, _: events.put(("command", m)))
        mine = [MISSION_START] + {"ignore": [], "refuse": [DO_PAUSE_CONTINUE]}.get(
            args.hold, [DO_PAUSE_CONTINUE, DO_SET_MODE]
        )
        for command in mine:
            self.direct.subscribe_command(command, lambda m, _: events.put(("answer", m)))
        self.action = None
        if args.hold == "refuse":
            self.action = ActionServer(component)
            # Every mode allowed, Hold too: MAVSDK 4.1 refuses Hold all the same.
            self.action.set_allowable_flight_modes(AllowableFlightModes(*[True] * 7))
            on_mode = lambda r, mode, _: events.put(("mode", r, mode))  # noqa: E731
            self.action.subscribe_flight_mode_change(on_mode)

    # -- events from MAVSDK --------------------------------------------------------------------

    def handle(self, event):
        kind = event[0]
        if kind == "upload":
            self.on_upload(event[1], event[2].mission_items)
        elif kind == "command":
            fields = json.loads(event[1].fields_json)
            params = [fields.get(f"param{i}") for i in range(1, 8)]
            record = {"event": "command", "command": fields.get("command"), "params": params}
            record["confirmation"] = fields.get("confirmation")
            self.pending.append([time.monotonic(), record])
        elif kind == "answer":
            self.answer(event[1])
        elif kind == "ack_out":
            self.acks.append((time.monotonic(), event[1], event[2]))
        elif kind == "mode":
            result, mode = event[1], event[2]
            emit({"event": "flight_mode_change", "result": result.name, "mode": mode.name})
            if result == ActionServerResult.SUCCESS and mode == FlightMode.MISSION:
                self.set_holding(False, "DO_SET_MODE")
        elif kind == "wire":
            emit(event[1])

    def on_upload(self, result, items):
        if result != MissionRawServerResult.SUCCESS:
            emit({"event": "upload_failed", "result": result.name})
            return
        rows = [{k: getattr(i, k) for k in vars(i)} for i in items]
        kind = items[0].mission_type if items else None
        if kind == 1:
            emit({"event": "fence", "items": rows})
        elif kind == 2:
            emit({"event": "rally", "items": rows})
        elif kind == 0:
            # MissionRawServer now counts from item 0 again; the vehicle waits for MISSION_START.
            self.items, self.mavsdk_seq, self.arrived = rows, 0, False
            self.runner.stop()
            emit({"event": "mission", "items": rows})
        else:
            emit({"event": "empty_upload"})  # no item says which list it was

    def answer(self, message):
        """Answers a command MAVSDK leaves to us (see the module doc)."""
        fields = json.loads(message.fields_json)
        command, p = fields["command"], [fields.get(f"param{i}", 0.0) for i in range(1, 8)]
        result = UNSUPPORTED
        if command == MISSION_START:
            result = self.start(int(p[0])) if self.items else DENIED
        elif command == DO_PAUSE_CONTINUE and self.args.hold == "accept":
            result = self.set_holding(p[0] == 0, "DO_PAUSE_CONTINUE")
        elif command == DO_SET_MODE and int(p[0]) & 1 and int(p[1]) == PX4_AUTO:
            sub = int(p[2])
            if sub in (PX4_LOITER, PX4_MISSION):
                result = self.set_holding(sub == PX4_LOITER, "DO_SET_MODE")
        ack = {"command": command, "result": result, "progress": 255, "result_param2": 0}
        ack.update(target_system=message.system_id, target_component=message.component_id)
        to = (message.system_id, message.component_id)
        self.direct.send_message(MavlinkMessage("COMMAND_ACK", 0, 0, *to, json.dumps(ack)))

    # -- the vehicle ---------------------------------------------------------------------------

    def start(self, first):
        track = self.runner.start(self.items, self.args.default_speed, self.runner.home[2], first)
        while self.mavsdk_seq < first:  # MissionRawServer can only move on one item at a time
            self.complete()
        self.arrived = False
        emit({"event": "started", "first": first, "legs": [leg.report() for leg in track.legs]})
        return ACCEPTED

    def set_holding(self, hold, by):
        if hold != self.runner.holding:
            self.runner.holding = hold
            emit({"event": "holding" if hold else "resumed", "by": by, **self.runner.report()})
        return ACCEPTED

    def complete(self):
        self.missions.set_current_item_complete()
        self.mavsdk_seq += 1

    def step(self, dt):
        self.runner.advance(dt)
        for seq in self.runner.newly_completed():
            while self.mavsdk_seq <= seq:
                self.complete()
        if self.runner.finished and not self.arrived:
            self.arrived = True
            emit({"event": "arrived", **self.runner.report()})

    def publish(self):
        lat, lon, alt = self.runner.here
        east, north, up = self.runner.velocity()
        self.telemetry.publish_position(
            Position(lat, lon, alt, alt - self.runner.home[2]),
            VelocityNed(north, east, -up),
            Heading(self.runner.heading_deg),
        )

    def flush_commands(self, now):
        """Prints each command with the ack sent for it, or without one once ACK_WAIT_S is over."""
        for entry in self.pending:
            record = entry[1]
            match = next((a for a in self.acks if a[1] == record["command"]), None)
            if match is not None:
                self.acks.remove(match)
                record["result"] = match[2]
            elif now - entry[0] > ACK_WAIT_S:
                record["result"] = None
        for entry in [e for e in self.pending if "result" in e[1]]:
            self.pending.remove(entry)
            emit(entry[1])
        self.acks = [a for a in self.acks if now - a[0] < 5.0]  # acks to commands not shown


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("port", type=int)
    ap.add_argument("--hold", choices=["ignore", "accept", "refuse"], default="ignore")
    ap.add_argument("--autopilot", choices=["generic", "px4"], default="generic")
    ap.add_argument("--home", type=vk.parse_home, default=(43.1, 5.9, 0.0), help="LAT,LON,ALT")
    ap.add_argument("--default-speed", type=float, default=1.0, help="m/s, until DO_CHANGE_SPEED")
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--ignore-stdin", action="store_true")
    args = ap.parse_args()

    events, stop = queue.Queue(), threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    if not args.ignore_stdin:
        threading.Thread(target=lambda: (sys.stdin.read(), stop.set()), daemon=True).start()
    wire = Wire(args.port, MAV_AUTOPILOT_PX4 if args.autopilot == "px4" else None, events)
    mavsdk, config = make_mavsdk()
    mavsdk.add_any_connection("raw://")
    mavsdk.subscribe_raw_bytes_to_be_sent(wire.outgoing)
    vehicle = Vehicle(args, mavsdk, wire, events)
    ids = {"system": config.system_id, "component": config.component_id}
    listening = {"event": "listening", "port": args.port, "mavsdk": mavsdk.version(), **ids}
    emit({**listening, "autopilot": args.autopilot, "hold": args.hold})

    began = last = last_publish = last_report = time.monotonic()
    code = 0
    while not stop.is_set():
        wire.receive(mavsdk, 0.02)
        while not events.empty():
            vehicle.handle(events.get())
        now = time.monotonic()
        vehicle.step(now - last)
        last = now
        if now - last_publish >= 0.1:
            last_publish = now
            vehicle.publish()
        if now - last_report >= 1.0:
            last_report = now
            emit({"event": "position", **vehicle.runner.report()})
        vehicle.flush_commands(now)
        if now - began > args.timeout:
            emit({"event": "timeout"})
            code = 2
            break
    if code == 0:
        emit({"event": "stopped"})
    mavsdk.destroy()
    return code


if __name__ == "__main__":
    sys.exit(main())
