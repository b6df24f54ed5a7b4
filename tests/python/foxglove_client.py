"""Independent Foxglove WebSocket client for Shoal's live server: the `websockets` package
(17.4) speaks the published protocol `foxglove.websocket.v1` (github.com/foxglove/ws-protocol)
and `jsonschema` (4.26.0) checks every advertised schema and validates every message against
its channel's schema. Nothing here is Shoal's code.

    python foxglove_client.py URL OUT.json [--timeout SECONDS]

It connects (retrying while the server is not up yet), subscribes to every channel advertised
(and to those advertised later), and reads until the server closes the connection at the end of
the mission. Once it has seen 20 poses it also checks, on connections of its own:

- a late client: subscribing mid-mission, it gets each channel's latest message at once (the
  scene with its obstacles, the status, each vehicle's pose);
- refusals: a handshake without the subprotocol is refused (HTTP 400); a malformed message and
  a subscription of an unknown channel are answered with a warning status and the connection
  stays; a message over 64 KiB closes the connection (close code 1009).

Writes OUT.json: the channels, every pose and location fix received (`[stamp_ns, ...]`), the
last scene's entities, counts of statuses and events, and the checks' results. Exit 0 when every
message was valid and every check passed, 1 otherwise (the reason on stderr).
"""

import argparse
import json
import struct
import sys
import time

import jsonschema
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

SUBPROTOCOL = "foxglove.websocket.v1"
MESSAGE_DATA = struct.Struct("<BIQ")


class Failed(Exception):
    pass


def need(ok, what):
    if not ok:
        raise Failed(what)


def connect_retrying(url, deadline):
    while True:
        try:
            return connect(url, subprotocols=[SUBPROTOCOL], open_timeout=5, max_size=None)
        except (OSError, TimeoutError):
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


class Client:
    """One connection: its channels, its subscriptions and what it received."""

    def __init__(self, ws):
        self.ws = ws
        self.channels = {}  # id -> advertised channel
        self.validators = {}  # id -> jsonschema validator
        self.subscriptions = {}  # subscription id -> channel id
        self.next_sub = 1
        self.info = None
        self.statuses = []

    def on_text(self, text):
        m = json.loads(text)
        op = m.get("op")
        if op == "serverInfo":
            self.info = m
        elif op == "advertise":
            new = []
            for c in m["channels"]:
                need(c["encoding"] == "json", f"{c['topic']}: encoding {c['encoding']!r}")
                need(c["schemaEncoding"] == "jsonschema", f"{c['topic']}: {c['schemaEncoding']!r}")
                schema = json.loads(c["schema"])
                jsonschema.Draft202012Validator.check_schema(schema)
                self.validators[c["id"]] = jsonschema.Draft202012Validator(schema)
                self.channels[c["id"]] = c
                new.append(c["id"])
            self.subscribe(new)
        elif op == "unadvertise":
            for i in m["channelIds"]:
                self.channels.pop(i, None)
        elif op == "status":
            self.statuses.append(m)
        else:
            raise Failed(f"unknown op {op!r}")

    def subscribe(self, channel_ids):
        subs = []
        for c in channel_ids:
            subs.append({"id": self.next_sub, "channelId": c})
            self.subscriptions[self.next_sub] = c
            self.next_sub += 1
        if subs:
            self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))

    def on_binary(self, data):
        """The channel and the validated message of a message-data frame."""
        opcode, sub, stamp = MESSAGE_DATA.unpack_from(data)
        need(opcode == 1, f"binary opcode {opcode}")
        need(sub in self.subscriptions, f"a message for subscription {sub}, never made")
        channel = self.channels.get(self.subscriptions[sub])
        need(channel is not None, f"a message on an unadvertised channel (subscription {sub})")
        message = json.loads(data[MESSAGE_DATA.size:])
        for e in self.validators[channel["id"]].iter_errors(message):
            path = "/".join(str(p) for p in e.absolute_path)
            raise Failed(f"{channel['topic']}: {path}: {e.message}")
        return channel, stamp, message


def stamp_of(message):
    t = message["timestamp"]
    return t["sec"] * 1_000_000_000 + t["nsec"]


class Mission:
    """What the main connection received."""

    def __init__(self):
        self.poses = {}
        self.locations = {}
        self.scene = None
        self.scenes = 0
        self.statuses = 0
        self.events = []

    def take(self, channel, stamp, m):
        schema = channel["schemaName"]
        topic = channel["topic"]
        if schema == "foxglove.PoseInFrame":
            need(stamp_of(m) == stamp, f"{topic}: header time {stamp} != message's")
            need(m["frame_id"] == "shoal", f"{topic}: frame {m['frame_id']!r}")
            p = m["pose"]["position"]
            vehicle = topic.rsplit("/", 1)[1]
            self.poses.setdefault(vehicle, []).append([stamp, p["x"], p["y"], p["z"]])
        elif schema == "foxglove.LocationFix":
            need(stamp_of(m) == stamp, f"{topic}: header time {stamp} != message's")
            vehicle = topic.rsplit("/", 1)[1]
            fix = [stamp, m["latitude"], m["longitude"], m["altitude"]]
            self.locations.setdefault(vehicle, []).append(fix)
        elif schema == "foxglove.SceneUpdate":
            self.scene = m
            self.scenes += 1
        elif topic == "/shoal/status":
            self.statuses += 1
        elif topic == "/shoal/events":
            self.events.append(m["kind"])


def late_client(url):
    """A client that connects mid-mission gets each channel's latest message at once."""
    with connect(url, subprotocols=[SUBPROTOCOL], open_timeout=5, max_size=None) as ws:
        c = Client(ws)
        got = {}
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            try:
                frame = ws.recv(timeout=0.5)
            except TimeoutError:
                continue
            if isinstance(frame, str):
                c.on_text(frame)
                continue
            channel, _, message = c.on_binary(frame)
            got.setdefault(channel["topic"], message)
            wanted = {ch["topic"] for ch in c.channels.values() if ch["topic"] != "/shoal/events"}
            if wanted <= set(got):
                break
        scene = got.get("/shoal/scene", {"entities": []})
        return {
            "topics": sorted(got),
            "scene_entities": [e["id"] for e in scene["entities"]],
        }


def refusals(url):
    """What the server refuses, and how."""
    out = {}
    try:
        with connect(url, open_timeout=5):
            out["no_subprotocol"] = "accepted"
    except InvalidStatus as e:
        out["no_subprotocol"] = e.response.status_code
    with connect(url, subprotocols=[SUBPROTOCOL], open_timeout=5, max_size=None) as ws:
        c = Client(ws)
        ws.send("not json")
        ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 99, "channelId": 9999}]}))
        deadline = time.monotonic() + 5
        while len(c.statuses) < 2 and time.monotonic() < deadline:
            try:
                frame = ws.recv(timeout=0.5)
            except TimeoutError:
                continue
            if isinstance(frame, str):
                c.on_text(frame)
        out["warnings"] = [s["message"] for s in c.statuses if s["level"] == 1]
        ws.send("x" * (64 * 1024 + 1))
        try:
            while True:
                ws.recv(timeout=5)
        except ConnectionClosed as e:
            out["oversize_close_code"] = e.rcvd.code if e.rcvd else None
        except TimeoutError:
            out["oversize_close_code"] = "still open"
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("url")
    ap.add_argument("out")
    ap.add_argument("--timeout", type=float, default=180.0)
    ap.add_argument(
        "--watch-only",
        action="store_true",
        help="only watch: no late client and no refusal checks (a fast replay may end first)",
    )
    args = ap.parse_args()
    deadline = time.monotonic() + args.timeout
    mission = Mission()
    checks = {}
    with connect_retrying(args.url, deadline) as ws:
        need(ws.subprotocol == SUBPROTOCOL, f"subprotocol {ws.subprotocol!r}")
        main_client = Client(ws)
        while True:
            need(time.monotonic() < deadline, "the mission did not end in time")
            try:
                frame = ws.recv(timeout=1)
            except TimeoutError:
                continue
            except ConnectionClosed:
                break
            if isinstance(frame, str):
                main_client.on_text(frame)
                continue
            mission.take(*main_client.on_binary(frame))
            seen = sum(len(p) for p in mission.poses.values())
            if not args.watch_only and not checks and seen >= 20:
                checks["late"] = late_client(args.url)
                checks["refusals"] = refusals(args.url)
    need(main_client.info is not None, "no serverInfo")
    summary = {
        "server": main_client.info["name"],
        "channels": {c["topic"]: c["schemaName"] for c in main_client.channels.values()},
        "poses": mission.poses,
        "locations": mission.locations,
        "scene_entities": [
            {"id": e["id"], "metadata": {kv["key"]: kv["value"] for kv in e["metadata"]}}
            for e in (mission.scene or {"entities": []})["entities"]
        ],
        "scenes": mission.scenes,
        "statuses": mission.statuses,
        "events": mission.events,
        "checks": checks,
    }
    with open(args.out, "w") as f:
        json.dump(summary, f)


if __name__ == "__main__":
    try:
        main()
    except (Failed, jsonschema.ValidationError, jsonschema.SchemaError) as e:
        print(f"foxglove_client: {e}", file=sys.stderr)
        sys.exit(1)
